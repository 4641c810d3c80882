#include "runtime/graph/graph_sample.hpp"

#include <cmath>

#include "runtime/graph/graph_path.hpp"

namespace marionette {

namespace {
// Frame `index` of edge `edge`, its source placed by `world`; an index at or past
// the edge's end is the target node's frame, placed as the edge leaves it.
void pose_at(const MotionGraph& graph, int edge, int index, const PlanarTransform& world, LocalPoseOutput out,
             std::span<const float> warps) {
    const GraphEdge& e = graph.edges[static_cast<size_t>(edge)];
    if (index >= e.frames) {
        const PlanarTransform after = e.kind == GraphEdgeKind::transition ? compose_planar(world, edge_alignment(e)) : world;
        const GraphNode& n = graph.nodes[static_cast<size_t>(e.to)];
        graph_frame_pose(graph, graph.clips[static_cast<size_t>(n.clip)].first_frame + n.frame, after, out.rotations,
                         out.translations);
    } else if (e.kind == GraphEdgeKind::transition) {
        const size_t width = 2 * static_cast<size_t>(graph.window_frames);
        graph_transition_pose(graph, e, index, world, out.rotations, out.translations,
                              warps.empty() ? warps : warps.subspan(static_cast<size_t>(edge) * width, width));
    } else {
        const GraphNode& n = graph.nodes[static_cast<size_t>(e.from)];
        graph_frame_pose(graph, graph.clips[static_cast<size_t>(n.clip)].first_frame + n.frame + index, world,
                         out.rotations, out.translations);
    }
}

bool has_joints(LocalPoseOutput pose, size_t joints) {
    return pose.rotations.size() == joints && pose.translations.size() == joints;
}
}  // namespace

bool GraphSampleJob::validate() const {
    if (!graph || edge < 0 || static_cast<size_t>(edge) >= graph->edges.size()) return false;
    const size_t joints = static_cast<size_t>(graph->joint_count());
    const float frames = static_cast<float>(graph->edges[static_cast<size_t>(edge)].frames);
    const size_t warps = graph->edges.size() * 2 * static_cast<size_t>(graph->window_frames);
    return edge_position >= 0.0f && edge_position <= frames && has_joints(scratch, joints) && has_joints(output, joints) &&
           (transition_warps.empty() || transition_warps.size() == warps);
}

bool GraphSampleJob::run() const {
    if (!validate()) return false;
    const int index = static_cast<int>(edge_position);
    const float u = edge_position - static_cast<float>(index);
    pose_at(*graph, edge, index, world, output, transition_warps);
    pose_at(*graph, edge, index + 1, world, scratch, transition_warps);
    for (size_t j = 0; j < output.rotations.size(); ++j) {
        output.rotations[j] = quat_slerp(output.rotations[j], scratch.rotations[j], u);
        output.translations[j] = lerp(output.translations[j], scratch.translations[j], u);
    }
    return true;
}

}  // namespace marionette
