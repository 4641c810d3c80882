#include "graph_builder/graph_builder.hpp"

#include <xxhash.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <thread>

#include <fmt/format.h>

namespace marionette::offline {

std::string describe_params(const GraphBuildParams& p) {
    return fmt::format("rate={} k={} h={} pct={} abs={} ch={} cs={}", p.analysis_rate_hz, p.window_frames,
                       p.neighbourhood_frames, p.threshold_percentile, p.threshold_absolute, p.contact_height,
                       p.contact_speed);
}

std::uint64_t graph_source_hash(std::uint64_t content_hash, const GraphBuildParams& params) {
    XXH64_state_t* h = XXH64_createState();
    XXH64_reset(h, content_hash);
    const std::string p = describe_params(params);
    XXH64_update(h, p.data(), p.size());
    const std::uint64_t hash = XXH64_digest(h);
    XXH64_freeState(h);
    return hash;
}

double skeleton_leg_length(const Skeleton& s, int foot) {
    double length = 0.0;
    if (foot >= 0) {
        for (int j = foot; j >= 0 && s.parents[static_cast<size_t>(j)] != kNoParent; j = s.parents[static_cast<size_t>(j)])
            length += glm::length(s.rest_offsets[static_cast<size_t>(j)]);
    } else {
        std::vector<vec3> p(s.parents.size());
        for (size_t j = 0; j < p.size(); ++j) {
            p[j] = s.parents[j] == kNoParent ? vec3(0.0f) : p[static_cast<size_t>(s.parents[j])] + s.rest_offsets[j];
            length = std::max(length, static_cast<double>(glm::length(p[j])));
        }
    }
    return length > 0.0 ? length : 1.0;
}

std::vector<std::uint8_t> detect_foot_contacts(std::span<const vec3> positions, int joints, int frames, double rate,
                                               int left, int right, double leg, const GraphBuildParams& p) {
    std::vector<std::uint8_t> out(static_cast<size_t>(frames), 0);
    const auto pos = [&](int f, int j) { return positions[static_cast<size_t>(f) * static_cast<size_t>(joints) + static_cast<size_t>(j)]; };
    float ground = std::numeric_limits<float>::max();
    for (int f = 0; f < frames; ++f)
        for (int j : {left, right})
            if (j >= 0) ground = std::min(ground, pos(f, j).y);
    for (int f = 0; f < frames; ++f) {
        const int a = std::max(f - 1, 0), b = std::min(f + 1, frames - 1);
        for (int side = 0; side < 2; ++side) {
            const int j = side == 0 ? left : right;
            if (j < 0 || b == a) continue;
            const vec3 d = pos(b, j) - pos(a, j);
            const double speed = std::sqrt(static_cast<double>(d.x) * d.x + static_cast<double>(d.z) * d.z) * rate / (b - a);
            const double height = pos(f, j).y - ground;
            if (height < p.contact_height * leg && speed < p.contact_speed * leg)
                out[static_cast<size_t>(f)] |= side == 0 ? kContactLeft : kContactRight;
        }
    }
    return out;
}

namespace {

struct PlacedTransition {
    TransitionCandidate candidate;
    PlanarTransform align;
};

// Nodes at every split point (clip ends, departures (A, i), arrivals (B, j+1)),
// keyed by global frame; clip edges between consecutive split points of a clip;
// one transition edge per candidate.
void assemble_graph(MotionGraph& g, const FrameFeatures& features, const std::vector<PlacedTransition>& transitions,
                    int k) {
    std::vector<std::int32_t> splits;
    splits.reserve(2 * g.clips.size() + 2 * transitions.size());
    for (const GraphClip& c : g.clips) splits.push_back(c.first_frame), splits.push_back(c.first_frame + c.frame_count - 1);
    for (const PlacedTransition& t : transitions) {
        splits.push_back(t.candidate.from_frame);
        splits.push_back(t.candidate.to_frame + 1);
    }
    std::sort(splits.begin(), splits.end());
    splits.erase(std::unique(splits.begin(), splits.end()), splits.end());
    const auto node_of = [&](std::int32_t global) {
        return static_cast<std::int32_t>(std::lower_bound(splits.begin(), splits.end(), global) - splits.begin());
    };
    g.nodes.reserve(splits.size());
    for (size_t n = 0; n < splits.size(); ++n) {
        const std::int32_t clip = features.clip_of[static_cast<size_t>(splits[n])];
        g.nodes.push_back({clip, splits[n] - g.clips[static_cast<size_t>(clip)].first_frame});
        if (n > 0 && g.nodes[n - 1].clip == clip) {
            GraphEdge e;
            e.from = static_cast<std::int32_t>(n - 1);
            e.to = static_cast<std::int32_t>(n);
            e.kind = GraphEdgeKind::clip;
            e.frames = splits[n] - splits[n - 1];
            g.edges.push_back(e);
        }
    }
    for (const PlacedTransition& t : transitions) {
        GraphEdge e;
        e.from = node_of(t.candidate.from_frame);
        e.to = node_of(t.candidate.to_frame + 1);
        e.kind = GraphEdgeKind::transition;
        e.frames = k;
        e.cost = t.candidate.distance;
        e.align_angle = static_cast<float>(t.align.angle);
        e.align_dx = static_cast<float>(t.align.dx);
        e.align_dz = static_cast<float>(t.align.dz);
        g.edges.push_back(e);
    }
    index_edges(g);
}

constexpr int kMaxBridgeRounds = 64;  // rounds of adding bridges before the build keeps what it has

// The thresholds (the distance percentiles, or the absolute threshold), then
// the tiled search for local minima below the bridge threshold. Returns how
// many window pairs the search compared.
std::int64_t search_transitions(const FrameFeatures& features, const GraphBuildParams& params, const GraphBuildHooks& hooks,
                                GraphBuildOutput& out) {
    const std::vector<double> percentiles =
        distance_percentiles(features, {params.threshold_percentile, params.bridge_percentile}, 65536, params.threads);
    out.threshold = params.threshold_absolute > 0.0 ? params.threshold_absolute : percentiles[0];
    out.bridge_threshold = std::max(out.threshold, percentiles[1]);

    CandidateSearchOptions search;
    search.neighbourhood = params.neighbourhood_frames;
    search.threshold = out.threshold;
    search.bridge_threshold = out.bridge_threshold;
    search.tile = params.tile;
    search.threads = params.threads;
    search.progress = hooks.progress;
    if (hooks.plot_size > 0) {
        out.plot_size = std::min<int>(hooks.plot_size, features.frames);
        search.plot_size = out.plot_size;
        search.plot = &out.plot;
    }
    CandidateSearchResult found = find_transition_candidates(features, search);
    out.candidates = std::move(found.candidates);
    return found.pair_evaluations;
}

// The graph's skeleton and metadata from the database, and every clip's frames
// one after another with their foot contacts (no nodes or edges yet).
void copy_clips(const ClipDatabase& db, const std::vector<vec3>& positions, double leg, const GraphBuildParams& params,
                MotionGraph& g) {
    const int J = db.skeleton.joint_count();
    g.skeleton = db.skeleton;
    g.animated_translation = db.animated_translation;
    g.length_unit = db.length_unit;
    g.frame_rate = db.analysis_rate_hz;
    g.window_frames = params.window_frames;
    g.leg_length = static_cast<float>(leg);
    g.left_foot = db.left_foot;
    g.right_foot = db.right_foot;
    g.labels = db.labels;
    std::int32_t first = 0;
    for (size_t c = 0; c < db.clips.size(); ++c) {
        const Clip& clip = db.clips[c];
        g.clips.push_back({clip.name, db.label_masks[c], first, clip.frame_count});
        g.rotations.insert(g.rotations.end(), clip.rotations.begin(), clip.rotations.end());
        g.translations.insert(g.translations.end(), clip.translations.begin(), clip.translations.end());
        const std::vector<std::uint8_t> contacts = detect_foot_contacts(
            std::span<const vec3>(positions.data() + static_cast<size_t>(first) * static_cast<size_t>(J),
                                  static_cast<size_t>(clip.frame_count) * static_cast<size_t>(J)),
            J, clip.frame_count, db.analysis_rate_hz, db.left_foot, db.right_foot, leg, params);
        g.contacts.insert(g.contacts.end(), contacts.begin(), contacts.end());
        first += clip.frame_count;
    }
}

// Usable candidates (something to continue with after the arrival), each placed
// once by the closed-form alignment of its windows, in parallel.
std::vector<PlacedTransition> place_candidates(const ClipDatabase& db, const std::vector<vec3>& positions,
                                               const FrameFeatures& features,
                                               const std::vector<TransitionCandidate>& candidates,
                                               const GraphBuildParams& params) {
    std::vector<PlacedTransition> placed;
    for (const TransitionCandidate& t : candidates) {
        const std::int32_t arrival = t.to_frame + 1;
        if (arrival >= features.frames ||
            features.clip_of[static_cast<size_t>(arrival)] != features.clip_of[static_cast<size_t>(t.to_frame)])
            continue;
        placed.push_back({t, {}});
    }
    const unsigned threads =
        std::max(1u, params.threads > 0 ? static_cast<unsigned>(params.threads) : std::thread::hardware_concurrency());
    const auto work = [&](unsigned w) {
        for (size_t c = w; c < placed.size(); c += threads)
            placed[c].align = reference_pair_alignment(db, positions, params.window_frames, placed[c].candidate.from_frame,
                                                       placed[c].candidate.to_frame);
    };
    std::vector<std::thread> workers;  // the calling thread is worker 0
    for (unsigned w = 1; w < threads; ++w) workers.emplace_back(work, w);
    work(0);
    for (std::thread& t : workers) t.join();
    return placed;
}

// The candidates above the threshold, cheapest first (ties by frames, so every
// machine picks the same), indexed by the clip each arrives in and each leaves.
struct BridgePool {
    std::vector<PlacedTransition> bridges;
    std::vector<bool> used;
    std::vector<std::vector<size_t>> arriving, leaving;
};

BridgePool make_bridge_pool(std::vector<PlacedTransition> bridges, const FrameFeatures& features, size_t clip_count) {
    std::sort(bridges.begin(), bridges.end(), [](const PlacedTransition& x, const PlacedTransition& y) {
        const TransitionCandidate &a = x.candidate, &b = y.candidate;
        return a.distance != b.distance ? a.distance < b.distance
                                        : (a.from_frame != b.from_frame ? a.from_frame < b.from_frame : a.to_frame < b.to_frame);
    });
    BridgePool pool;
    pool.bridges = std::move(bridges);
    pool.used.assign(pool.bridges.size(), false);
    pool.arriving.resize(clip_count);
    pool.leaving.resize(clip_count);
    for (size_t b = 0; b < pool.bridges.size(); ++b) {
        const TransitionCandidate& t = pool.bridges[b].candidate;
        pool.arriving[static_cast<size_t>(features.clip_of[static_cast<size_t>(t.to_frame)])].push_back(b);
        pool.leaving[static_cast<size_t>(features.clip_of[static_cast<size_t>(t.from_frame)])].push_back(b);
    }
    return pool;
}

// Which clips the pruned graph kept.
std::vector<bool> kept_clips(const MotionGraph& g) {
    std::vector<bool> kept(g.clips.size(), false);
    for (const std::string& name : kept_clip_names(g)) kept[static_cast<size_t>(g.clip_index(name))] = true;
    return kept;
}

// Frames on the pruned graph's clip edges: a bridge must leave from and arrive on one.
std::vector<bool> frames_on_clip_edges(const MotionGraph& g, const FrameFeatures& features) {
    std::vector<bool> on_kept(static_cast<size_t>(features.frames), false);
    for (const GraphEdge& e : g.edges)
        if (e.kind == GraphEdgeKind::clip) {
            const GraphNode& n = g.nodes[static_cast<size_t>(e.from)];
            const std::int32_t f0 = g.clips[static_cast<size_t>(n.clip)].first_frame + n.frame;
            for (std::int32_t f = f0; f <= f0 + e.frames; ++f) on_kept[static_cast<size_t>(f)] = true;
        }
    return on_kept;
}

// The cheapest unused pair for cut-off clip c: a bridge arriving in it (from the
// kept graph) no later than another leaves it (back onto the kept graph).
// False when there is none.
bool cheapest_bridge_pair(const BridgePool& pool, size_t c, const std::vector<bool>& on_kept, size_t& best_in,
                          size_t& best_out) {
    best_in = pool.bridges.size();
    best_out = pool.bridges.size();
    double best = std::numeric_limits<double>::infinity();
    for (size_t bi : pool.arriving[c]) {
        const TransitionCandidate& in = pool.bridges[bi].candidate;
        if (pool.used[bi] || !on_kept[static_cast<size_t>(in.from_frame)]) continue;
        for (size_t bo : pool.leaving[c]) {
            const TransitionCandidate& leave = pool.bridges[bo].candidate;
            // Usable candidates arrive inside their clip (place_candidates), so to_frame + 1 exists.
            if (pool.used[bo] || !on_kept[static_cast<size_t>(leave.to_frame + 1)] || leave.from_frame < in.to_frame + 1)
                continue;
            const double cost = static_cast<double>(in.distance) + leave.distance;
            if (cost < best) best = cost, best_in = bi, best_out = bo;
        }
    }
    return best_in != pool.bridges.size();
}

// One bridge pair into and out of each clip the pruned graph lost; false when
// no such pair was left.
bool add_bridges(const MotionGraph& g, const FrameFeatures& features, BridgePool& pool,
                 std::vector<PlacedTransition>& chosen, std::int64_t& bridges_added) {
    const std::vector<bool> kept = kept_clips(g);
    const std::vector<bool> on_kept = frames_on_clip_edges(g, features);
    bool added = false;
    for (size_t c = 0; c < g.clips.size(); ++c) {
        size_t best_in = 0, best_out = 0;
        if (kept[c] || !cheapest_bridge_pair(pool, c, on_kept, best_in, best_out)) continue;
        for (size_t pick : {best_in, best_out}) {
            pool.used[pick] = true;
            chosen.push_back(pool.bridges[pick]);
            ++bridges_added;
        }
        added = true;
    }
    return added;
}

// The graph from the regular transitions, pruned to its largest component; then,
// while a clip is cut off from it, the cheapest bridge pair (local minima below
// the looser bridge threshold) into and out of that clip, until it joins or none
// is left.
void assemble_with_bridges(MotionGraph& g, const FrameFeatures& features, std::vector<PlacedTransition> chosen,
                           BridgePool pool, int k, GraphBuildOutput& out) {
    const MotionGraph base = g;
    for (int round = 0;; ++round) {
        g = base;
        assemble_graph(g, features, chosen, k);
        out.prune = prune_to_largest_component(g);
        if (round >= kMaxBridgeRounds) break;
        if (!add_bridges(g, features, pool, chosen, out.bridges)) break;
    }
}

void record_stats(MotionGraph& g, const GraphBuildOutput& out, std::int64_t pair_evaluations) {
    std::int64_t kept = 0;
    for (const GraphEdge& e : g.edges)
        if (e.kind == GraphEdgeKind::clip) kept += e.frames;
    g.stats.frames = out.frames;
    g.stats.pair_evaluations = pair_evaluations;
    g.stats.candidates = out.regular_candidates;
    g.stats.nodes_before = out.prune.nodes_before;
    g.stats.edges_before = out.prune.edges_before;
    g.stats.frames_kept = kept;
    g.stats.threshold = out.threshold;
    // Wall time would make the bytes of the same build differ run to run (and the
    // file's bytes enter the simulation's clip-data hash): callers measure it themselves.
    g.stats.build_seconds = 0.0;
}

}  // namespace

GraphBuildOutput build_motion_graph(const ClipDatabase& db, const GraphBuildParams& params, const GraphBuildHooks& hooks) {
    GraphBuildOutput out;
    const int k = params.window_frames;
    const double leg = skeleton_leg_length(db.skeleton, db.left_foot >= 0 ? db.left_foot : db.right_foot);
    const std::vector<vec3> positions = database_positions(db);
    const FrameFeatures features = compute_frame_features(db, positions, k, leg);
    out.frames = features.frames;
    const std::int64_t pair_evaluations = search_transitions(features, params, hooks, out);
    MotionGraph& g = out.graph;
    copy_clips(db, positions, leg, params, g);
    std::vector<PlacedTransition> chosen, bridges;
    for (const PlacedTransition& t : place_candidates(db, positions, features, out.candidates, params))
        (t.candidate.distance <= out.threshold ? chosen : bridges).push_back(t);
    out.regular_candidates = static_cast<std::int64_t>(chosen.size());
    BridgePool pool = make_bridge_pool(std::move(bridges), features, g.clips.size());
    assemble_with_bridges(g, features, std::move(chosen), std::move(pool), k, out);
    g.source_hash = graph_source_hash(db.content_hash, params);
    record_stats(g, out, pair_evaluations);
    return out;
}

}  // namespace marionette::offline
