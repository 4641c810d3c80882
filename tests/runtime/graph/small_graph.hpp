#pragma once
// A small hand-made motion graph shared by the run-time graph tests and the
// builder's pruning tests.
#include "runtime/graph/motion_graph.hpp"

namespace marionette::test {

// A two-joint graph over three clips: a loop in "a", a loop in "b" joined both
// ways, and a clip "c" that can only be entered (cut off by pruning).
inline MotionGraph small_graph() {
    MotionGraph g;
    g.skeleton.joint_names = {"root", "tip"};
    g.skeleton.parents = {kNoParent, 0};
    g.skeleton.rest_offsets = {vec3(0.0f), vec3(0.0f, 1.0f, 0.0f)};
    g.animated_translation = {true, false};
    g.window_frames = 2;
    g.frame_rate = 10.0;
    g.labels = {"run", "walk", "wave"};
    g.clips = {{"a", 2u, 0, 10}, {"b", 1u, 10, 10}, {"c", 4u, 20, 10}};
    for (int f = 0; f < 30; ++f) {
        g.rotations.push_back(quat_axis_angle(vec3(1, 0, 0), 0.05 * (f % 10)));
        g.rotations.push_back(quat_identity());
        g.translations.push_back(vec3(0.1f * (f % 10), 1.0f, 0.0f));
        g.translations.push_back(vec3(0.0f, 1.0f, 0.0f));
        g.contacts.push_back(static_cast<std::uint8_t>(f % 3 == 0 ? kContactLeft : 0));
    }
    // Nodes: a0 a4 a9 | b0 b4 b9 | c0 c9
    g.nodes = {{0, 0}, {0, 4}, {0, 9}, {1, 0}, {1, 4}, {1, 9}, {2, 0}, {2, 9}};
    const auto clip_edge = [&](int a, int b) {
        GraphEdge e;
        e.from = a, e.to = b, e.kind = GraphEdgeKind::clip;
        e.frames = g.nodes[static_cast<size_t>(b)].frame - g.nodes[static_cast<size_t>(a)].frame;
        g.edges.push_back(e);
    };
    const auto transition = [&](int a, int b, float cost) {
        GraphEdge e;
        e.from = a, e.to = b, e.kind = GraphEdgeKind::transition, e.frames = 2, e.cost = cost;
        g.edges.push_back(e);
    };
    clip_edge(0, 1), clip_edge(1, 2), clip_edge(3, 4), clip_edge(4, 5), clip_edge(6, 7);
    transition(1, 4, 0.1f);  // a4 → b4 (plays a4,a5 into b2,b3)
    transition(4, 1, 0.2f);  // b4 → a4
    transition(4, 7, 0.3f);  // b4 → c9: c is only entered (a dead end)
    index_edges(g);
    return g;
}

}  // namespace marionette::test
