#pragma once
// A small synthetic motion graph for controller tests and benchmarks (no data
// files, so it is the same on every build and machine): a two-joint body with
// clips that walk straight, curve left, curve right, stand, and wave (labelled
// "wave"), joined by transitions from frame 9 of every clip (4 blended frames) to frame 4 of every
// clip, each aligned so the target clip continues where the source is.
#include "runtime/math/det_math.hpp"

#include "runtime/graph/motion_graph.hpp"

namespace marionette::test {

inline MotionGraph make_locomotion_graph() {
    MotionGraph g;
    g.skeleton.joint_names = {"root", "arm"};
    g.skeleton.parents = {kNoParent, 0};
    g.skeleton.rest_offsets = {vec3(0.0f), vec3(0.0f, 1.0f, 0.0f)};
    g.animated_translation = {true, false};
    g.window_frames = 4;
    g.frame_rate = 30.0;
    g.labels = {"walk", "idle", "wave"};
    struct Spec { const char* name; std::uint32_t labels; double step, turn, arm; };
    const Spec specs[] = {{"straight", 1u, 0.04, 0.0, 0.0}, {"left", 1u, 0.04, 0.06, 0.0}, {"right", 1u, 0.04, -0.06, 0.0},
                          {"stand", 2u, 0.0, 0.0, 0.0},     {"wave", 4u, 0.0, 0.0, 0.08}};
    const int frames = 14;
    std::vector<vec3> at9;  // root position and yaw at frame 9 of each clip
    std::vector<double> yaw9;
    for (const Spec& s : specs) {
        GraphClip clip;
        clip.name = s.name;
        clip.label_mask = s.labels;
        clip.first_frame = static_cast<std::int32_t>(g.contacts.size());
        clip.frame_count = frames;
        g.clips.push_back(clip);
        double x = 0.0, z = 0.0, yaw = 0.0;
        for (int f = 0; f < frames; ++f) {
            if (f == 9) at9.push_back(vec3(static_cast<float>(x), 0.0f, static_cast<float>(z))), yaw9.push_back(yaw);
            g.rotations.push_back(quat_axis_angle(vec3(0.0f, 1.0f, 0.0f), yaw));
            g.rotations.push_back(quat_axis_angle(vec3(1.0f, 0.0f, 0.0f), s.arm * (f < 7 ? f : 13 - f)));
            g.translations.push_back(vec3(static_cast<float>(x), 1.0f, static_cast<float>(z)));
            g.translations.push_back(vec3(0.0f, 1.0f, 0.0f));
            g.contacts.push_back(static_cast<std::uint8_t>(f % 2 == 0 ? kContactLeft : kContactRight));
            x += s.step * det::sin(yaw), z += s.step * det::cos(yaw);
            yaw += s.turn;
        }
    }
    const int clips = static_cast<int>(g.clips.size());
    for (int c = 0; c < clips; ++c) g.nodes.push_back({c, 4}), g.nodes.push_back({c, 9});
    for (int a = 0; a < clips; ++a) {
        GraphEdge e;
        e.from = 2 * a, e.to = 2 * a + 1, e.kind = GraphEdgeKind::clip, e.frames = 5;
        g.edges.push_back(e);
        for (int b = 0; b < clips; ++b) {
            GraphEdge t;
            t.from = 2 * a + 1, t.to = 2 * b, t.kind = GraphEdgeKind::transition, t.frames = 4;
            t.cost = a == b ? 0.0f : 0.1f;
            // Frame 0 of b (at the origin, facing +Z) onto frame 9 of a.
            t.align_angle = static_cast<float>(yaw9[static_cast<size_t>(a)]);
            t.align_dx = at9[static_cast<size_t>(a)].x, t.align_dz = at9[static_cast<size_t>(a)].z;
            g.edges.push_back(t);
        }
    }
    index_edges(g);
    return g;
}

}  // namespace marionette::test
