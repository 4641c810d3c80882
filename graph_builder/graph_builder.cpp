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

}  // namespace

GraphBuildOutput build_motion_graph(const ClipDatabase& db, const GraphBuildParams& params, const GraphBuildHooks& hooks) {
    GraphBuildOutput out;
    const int k = params.window_frames;
    const int J = db.skeleton.joint_count();
    const double leg = skeleton_leg_length(db.skeleton, db.left_foot >= 0 ? db.left_foot : db.right_foot);
    const std::vector<vec3> positions = database_positions(db);
    const FrameFeatures features = compute_frame_features(db, positions, k, leg);
    out.frames = features.frames;
    const std::vector<double> percentiles =
        distance_percentiles(features, {params.threshold_percentile, params.bridge_percentile});
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
    out.candidates = found.candidates;

    MotionGraph& g = out.graph;
    g.skeleton = db.skeleton;
    g.animated_translation = db.animated_translation;
    g.length_unit = db.length_unit;
    g.frame_rate = db.analysis_rate_hz;
    g.window_frames = k;
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

    // Regular transitions below the threshold; then, while a clip is cut off
    // from the largest component, the cheapest bridge (a local minimum below the
    // looser bridge threshold) into and out of it, until it joins or none is left.
    // Usable candidates (something to continue with after the arrival), each placed
    // once by the closed-form alignment of its windows, in parallel.
    std::vector<PlacedTransition> placed;
    for (const TransitionCandidate& t : out.candidates) {
        const std::int32_t arrival = t.to_frame + 1;
        if (arrival >= features.frames ||
            features.clip_of[static_cast<size_t>(arrival)] != features.clip_of[static_cast<size_t>(t.to_frame)])
            continue;
        placed.push_back({t, {}});
    }
    {
        const unsigned threads = std::max(1u, params.threads > 0 ? static_cast<unsigned>(params.threads)
                                                                 : std::thread::hardware_concurrency());
        std::vector<std::thread> workers;
        for (unsigned w = 0; w < threads; ++w)
            workers.emplace_back([&, w] {
                for (size_t c = w; c < placed.size(); c += threads)
                    reference_pair_distance(db, positions, k, leg, placed[c].candidate.from_frame,
                                            placed[c].candidate.to_frame, &placed[c].align);
            });
        for (std::thread& t : workers) t.join();
    }
    std::vector<PlacedTransition> chosen, bridges;
    for (const PlacedTransition& t : placed) (t.candidate.distance <= out.threshold ? chosen : bridges).push_back(t);
    out.regular_candidates = static_cast<std::int64_t>(chosen.size());
    std::sort(bridges.begin(), bridges.end(), [](const PlacedTransition& x, const PlacedTransition& y) {
        const TransitionCandidate &a = x.candidate, &b = y.candidate;
        return a.distance != b.distance ? a.distance < b.distance
                                        : (a.from_frame != b.from_frame ? a.from_frame < b.from_frame : a.to_frame < b.to_frame);
    });
    std::vector<bool> used(bridges.size(), false);
    // Bridges by the clip they arrive in and the clip they leave.
    std::vector<std::vector<size_t>> arriving(g.clips.size()), leaving(g.clips.size());
    for (size_t b = 0; b < bridges.size(); ++b) {
        arriving[static_cast<size_t>(features.clip_of[static_cast<size_t>(bridges[b].candidate.to_frame)])].push_back(b);
        leaving[static_cast<size_t>(features.clip_of[static_cast<size_t>(bridges[b].candidate.from_frame)])].push_back(b);
    }
    const MotionGraph base = g;
    for (int round = 0;; ++round) {
        g = base;
        assemble_graph(g, features, chosen, k);
        out.prune = prune_to_largest_component(g);
        if (round >= 64) break;
        std::vector<bool> kept(g.clips.size(), false);
        for (const std::string& name : kept_clip_names(g)) kept[static_cast<size_t>(g.clip_index(name))] = true;
        // Frames on kept clip edges: a bridge must leave from and arrive on one.
        std::vector<bool> on_kept(static_cast<size_t>(features.frames), false);
        for (const GraphEdge& e : g.edges)
            if (e.kind == GraphEdgeKind::clip) {
                const GraphNode& n = g.nodes[static_cast<size_t>(e.from)];
                const std::int32_t f0 = g.clips[static_cast<size_t>(n.clip)].first_frame + n.frame;
                for (std::int32_t f = f0; f <= f0 + e.frames; ++f) on_kept[static_cast<size_t>(f)] = true;
            }
        bool added = false;
        for (size_t c = 0; c < g.clips.size(); ++c) {
            if (kept[c]) continue;
            // The cheapest pair: a bridge arriving in clip c no later than another leaves it.
            size_t best_in = bridges.size(), best_out = bridges.size();
            double best = std::numeric_limits<double>::infinity();
            for (size_t bi : arriving[c]) {
                const TransitionCandidate& in = bridges[bi].candidate;
                if (used[bi] || !on_kept[static_cast<size_t>(in.from_frame)]) continue;
                for (size_t bo : leaving[c]) {
                    const TransitionCandidate& leave = bridges[bo].candidate;
                    // Usable candidates arrive inside their clip (checked above), so to_frame + 1 exists.
                    if (used[bo] || !on_kept[static_cast<size_t>(leave.to_frame + 1)] ||
                        leave.from_frame < in.to_frame + 1)
                        continue;
                    const double cost = static_cast<double>(in.distance) + leave.distance;
                    if (cost < best) best = cost, best_in = bi, best_out = bo;
                }
            }
            if (best_in == bridges.size()) continue;
            for (size_t pick : {best_in, best_out}) {
                used[pick] = true;
                chosen.push_back(bridges[pick]);
                ++out.bridges;
            }
            added = true;
        }
        if (!added) break;
    }


    g.source_hash = graph_source_hash(db.content_hash, params);

    std::int64_t kept = 0;
    for (const GraphEdge& e : g.edges)
        if (e.kind == GraphEdgeKind::clip) kept += e.frames;
    g.stats.frames = out.frames;
    g.stats.pair_evaluations = found.pair_evaluations;
    g.stats.candidates = out.regular_candidates;
    g.stats.nodes_before = out.prune.nodes_before;
    g.stats.edges_before = out.prune.edges_before;
    g.stats.frames_kept = kept;
    g.stats.threshold = out.threshold;
    // Wall time would make the bytes of the same build differ run to run (and the
    // file's bytes enter the simulation's clip-data hash): callers measure it themselves.
    g.stats.build_seconds = 0.0;
    return out;
}

}  // namespace marionette::offline
