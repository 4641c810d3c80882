#pragma once
// The offline motion-graph build: database → frame features → tiled transition
// search → graph (clip edges between split points, transition edges with their
// alignment and cost) → pruning to the largest strongly connected component →
// foot contacts. The result is runtime/graph/motion_graph.hpp's plain data.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "graph_builder/clip_database.hpp"
#include "graph_builder/graph_prune.hpp"
#include "graph_builder/transition_search.hpp"
#include "runtime/graph/motion_graph.hpp"

namespace marionette::offline {

struct GraphBuildParams {
    double analysis_rate_hz = 30.0;
    int window_frames = 10;            // k
    int neighbourhood_frames = 4;      // local minimum over (2h+1)² pairs
    double threshold_percentile = 5.0; // used when threshold_absolute <= 0
    double threshold_absolute = 0.0;   // mean squared point distance, leg lengths²
    double bridge_percentile = 90.0;   // looser threshold for bridges into cut-off clips
    double contact_height = 0.08;      // foot joint above the clip's lowest foot height, leg lengths
    double contact_speed = 0.6;        // foot speed on the ground plane, leg lengths per second
    int tile = 512;
    int threads = 0;                   // 0: all cores
};

// Text of the parameters, hashed into the source hash.
std::string describe_params(const GraphBuildParams& params);

// The source hash a graph built from a database with this content hash and these
// parameters carries (MotionGraph::source_hash): lets a caller tell whether a
// .mgraph is stale without building.
std::uint64_t graph_source_hash(std::uint64_t content_hash, const GraphBuildParams& params);

struct GraphBuildOutput {
    MotionGraph graph;                 // pruned
    PruneReport prune;
    std::vector<TransitionCandidate> candidates;  // local minima below the bridge threshold
    std::int64_t frames = 0;
    double threshold = 0.0;
    double bridge_threshold = 0.0;
    std::int64_t regular_candidates = 0;  // of those, below the threshold
    std::int64_t bridges = 0;             // bridges added to reconnect cut-off clips
    std::vector<float> plot;           // when plot_size > 0
    int plot_size = 0;
};

struct GraphBuildHooks {
    std::function<void(double)> progress;  // 0 … 1 over the distance pass
    int plot_size = 0;
};

GraphBuildOutput build_motion_graph(const ClipDatabase& db, const GraphBuildParams& params, const GraphBuildHooks& hooks = {});

// Leg length of the skeleton at rest (sum of the rest offsets from a foot up to
// the root), or its largest joint distance from the root when it has no feet.
double skeleton_leg_length(const Skeleton& skeleton, int foot_joint);

// Per-frame foot contacts of one clip's world positions: the foot is below
// contact_height above the clip's lowest foot point and slower than contact_speed.
std::vector<std::uint8_t> detect_foot_contacts(std::span<const vec3> positions, int joints, int frames, double rate,
                                               int left_foot, int right_foot, double leg_length,
                                               const GraphBuildParams& params);

}  // namespace marionette::offline
