#pragma once
// Graph sampling as a job (runtime/anim/pose_spans.hpp): the local pose of a
// motion graph at a point along one of its edges, the two neighbouring frames
// (each a database frame, or a blended frame of a transition: graph_path.hpp)
// slerped and lerped, roots placed in the world by the edge source's placement.
// The graph controller runs it every tick; it never allocates.
#include <cstdint>

#include "runtime/anim/pose_spans.hpp"
#include "runtime/graph/motion_graph.hpp"
#include "runtime/math/planar_alignment.hpp"

namespace marionette {

struct GraphSampleJob {
    const MotionGraph* graph = nullptr;
    std::int32_t edge = -1;          // the edge being played
    float edge_position = 0.0f;      // graph frames into the edge, [0, edge.frames]
    PlanarTransform world;           // placement of the edge's source
    LocalPoseOutput scratch;         // the later of the two frames (joint_count entries each)
    LocalPoseOutput output;          // out: joint_count entries each, graph units
    // Per edge, 2·window_frames registered window times (transition_time_warp,
    // graph_path.hpp; GraphController's table); empty: transitions unwarped.
    std::span<const float> transition_warps;

    // False without a graph, for an edge not in it, a position off the edge,
    // spans not of the graph's joint count, or a warp table not of edges × 2k.
    bool validate() const;
    [[nodiscard]] bool run() const;
};

}  // namespace marionette
