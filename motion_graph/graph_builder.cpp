#include "motion_graph/graph_builder.hpp"

#include <xxhash.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include <fmt/format.h>

namespace marionette::graph {

std::string describe_params(const GraphBuildParams& p) {
    return fmt::format("rate={} k={} h={} pct={} abs={} ch={} cs={}", p.analysis_rate_hz, p.window_frames,
                       p.neighbourhood_frames, p.threshold_percentile, p.threshold_absolute, p.contact_height,
                       p.contact_speed);
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

// Nodes at every split point (clip ends, departures (A, i), arrivals (B, j+1)),
// clip edges between consecutive split points, one transition edge per candidate.
void assemble_graph(MotionGraph& g, const ClipDatabase& db, const std::vector<vec3>& positions,
                    const FrameFeatures& features, const std::vector<TransitionCandidate>& candidates, int k,
                    double leg) {
    // Split points per clip: both ends, every departure (A, i) and every arrival (B, j+1).
    const auto local = [&](std::int32_t global) {
        const std::int32_t c = features.clip_of[static_cast<size_t>(global)];
        return std::pair<std::int32_t, std::int32_t>(c, global - g.clips[static_cast<size_t>(c)].first_frame);
    };
    std::vector<std::set<std::int32_t>> splits(g.clips.size());
    for (size_t c = 0; c < g.clips.size(); ++c) splits[c] = {0, g.clips[c].frame_count - 1};
    std::vector<TransitionCandidate> usable;
    for (const TransitionCandidate& t : candidates) {
        const auto [ca, fa] = local(t.from_frame);
        const auto [cb, fb] = local(t.to_frame);
        if (fb + 1 >= g.clips[static_cast<size_t>(cb)].frame_count) continue;  // nothing to continue with after it
        splits[static_cast<size_t>(ca)].insert(fa);
        splits[static_cast<size_t>(cb)].insert(fb + 1);
        usable.push_back(t);
    }
    std::map<std::pair<std::int32_t, std::int32_t>, std::int32_t> node_of;
    for (size_t c = 0; c < g.clips.size(); ++c) {
        std::int32_t previous = -1;
        for (std::int32_t frame : splits[c]) {
            const std::int32_t id = static_cast<std::int32_t>(g.nodes.size());
            g.nodes.push_back({static_cast<std::int32_t>(c), frame});
            node_of[{static_cast<std::int32_t>(c), frame}] = id;
            if (previous >= 0) {
                GraphEdge e;
                e.from = previous;
                e.to = id;
                e.kind = GraphEdgeKind::clip;
                e.frames = frame - g.nodes[static_cast<size_t>(previous)].frame;
                g.edges.push_back(e);
            }
            previous = id;
        }
    }
    for (const TransitionCandidate& t : usable) {
        const auto [ca, fa] = local(t.from_frame);
        const auto [cb, fb] = local(t.to_frame);
        PlanarTransform align;
        reference_pair_distance(db, positions, k, leg, t.from_frame, t.to_frame, &align);
        GraphEdge e;
        e.from = node_of[{ca, fa}];
        e.to = node_of[{cb, fb + 1}];
        e.kind = GraphEdgeKind::transition;
        e.frames = k;
        e.cost = t.distance;
        e.align_angle = static_cast<float>(align.angle);
        e.align_dx = static_cast<float>(align.dx);
        e.align_dz = static_cast<float>(align.dz);
        g.edges.push_back(e);
    }
    index_edges(g);
}

}  // namespace

GraphBuildOutput build_motion_graph(const ClipDatabase& db, const GraphBuildParams& params, const GraphBuildHooks& hooks) {
    const auto started = std::chrono::steady_clock::now();
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
    std::vector<TransitionCandidate> chosen, bridges;
    for (const TransitionCandidate& t : out.candidates)
        (t.distance <= out.threshold ? chosen : bridges).push_back(t);
    out.regular_candidates = static_cast<std::int64_t>(chosen.size());
    std::sort(bridges.begin(), bridges.end(), [](const TransitionCandidate& a, const TransitionCandidate& b) {
        return a.distance != b.distance ? a.distance < b.distance
                                        : (a.from_frame != b.from_frame ? a.from_frame < b.from_frame : a.to_frame < b.to_frame);
    });
    std::vector<bool> used(bridges.size(), false);
    const MotionGraph base = g;
    for (int round = 0;; ++round) {
        g = base;
        assemble_graph(g, db, positions, features, chosen, k, leg);
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
            const std::int32_t clip = static_cast<std::int32_t>(c);
            size_t best_in = bridges.size(), best_out = bridges.size();
            double best = std::numeric_limits<double>::infinity();
            for (size_t bi = 0; bi < bridges.size(); ++bi) {
                const TransitionCandidate& in = bridges[bi];
                if (used[bi] || features.clip_of[static_cast<size_t>(in.to_frame)] != clip ||
                    !on_kept[static_cast<size_t>(in.from_frame)])
                    continue;
                for (size_t bo = 0; bo < bridges.size(); ++bo) {
                    const TransitionCandidate& leave = bridges[bo];
                    if (used[bo] || features.clip_of[static_cast<size_t>(leave.from_frame)] != clip ||
                        leave.to_frame + 1 >= features.frames || !on_kept[static_cast<size_t>(leave.to_frame + 1)] ||
                        features.clip_of[static_cast<size_t>(leave.to_frame + 1)] !=
                            features.clip_of[static_cast<size_t>(leave.to_frame)] ||
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


    XXH64_state_t* h = XXH64_createState();
    XXH64_reset(h, db.content_hash);
    const std::string p = describe_params(params);
    XXH64_update(h, p.data(), p.size());
    g.source_hash = XXH64_digest(h);
    XXH64_freeState(h);

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
    g.stats.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    return out;
}

}  // namespace marionette::graph
