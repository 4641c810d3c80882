#pragma once
// Pruning a freshly built motion graph to the part a controller can use
// forever: the largest strongly connected component. Offline only (graph builds).
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "runtime/graph/motion_graph.hpp"

namespace marionette {

// ---- strongly connected components and pruning ---------------------------------

// Tarjan's algorithm without recursion (an explicit stack), so a 1 000 000-node
// chain cannot overflow the call stack. Graph in CSR form: node n's successors are
// targets[begin[n] … begin[n+1]). component[n] is numbered in the order Tarjan
// completes components (reverse topological order of the condensation).
struct SccResult {
    std::vector<std::int32_t> component;
    std::int32_t count = 0;
};
SccResult strongly_connected_components(std::span<const std::int32_t> begin, std::span<const std::int32_t> targets);

struct LabelReachability {
    std::string label;
    int clips = 0;        // clips carrying the label
    int clips_kept = 0;   // of those, clips with frames in the kept component
    std::string reason;   // why it was cut off (empty when kept)
};

struct PruneReport {
    std::int64_t nodes_before = 0, edges_before = 0;
    std::int64_t nodes = 0, edges = 0;
    std::int64_t component_count = 0;
    std::vector<LabelReachability> labels;
};

// Keeps the largest strongly connected component (every kept node can reach every
// other, so no dead end survives), drops every other node and edge, renumbers, and
// reports, per label with clips, whether the component still reaches it.
PruneReport prune_to_largest_component(MotionGraph& graph);

// Names of clips with at least one kept clip edge.
std::vector<std::string> kept_clip_names(const MotionGraph& graph);

}  // namespace marionette
