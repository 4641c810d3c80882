// Registration of a transition's two windows by dynamic time warping
// (transition_time_warp, runtime/graph/graph_path.hpp; issue #14's time-warped
// blends). Generated cases (fixed seed): two clips of the same three-joint
// swing, the target's at 0.6–1.6× the source's rate and any phase, windows of
// 4–16 frames. The warp starts and ends where the plain blend does, never runs
// backwards, stays within its band; its DTW path costs no more than the
// diagonal's; identical windows give the identity exactly; and over the cases
// the warped pairs of poses are closer than the plain blend's.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <vector>

#include "runtime/graph/graph_path.hpp"
#include "runtime/graph/motion_graph.hpp"
#include "runtime/math/det_math.hpp"

using namespace marionette;

namespace {
// Clip 0: 60 frames of the swing at rate 1; clip 1: 60 frames at `rate` from
// `phase`. Nodes at source frame `from` and target frame `to`, one transition.
MotionGraph swing_graph(int k, double rate, double phase, int from, int to, int frames = 60) {
    MotionGraph g;
    g.skeleton.joint_names = {"root", "upper", "lower"};
    g.skeleton.parents = {kNoParent, 0, 1};
    g.skeleton.rest_offsets = {vec3(0.0f), vec3(0.0f, -0.4f, 0.0f), vec3(0.0f, -0.4f, 0.0f)};
    g.animated_translation = {true, false, false};
    g.window_frames = k;
    g.frame_rate = 30.0;
    g.labels = {"walk"};
    g.clips = {{"a", 1u, 0, frames}, {"b", 1u, frames, frames}};
    for (int c = 0; c < 2; ++c)
        for (int f = 0; f < frames; ++f) {
            const double t = c == 0 ? f * 0.25 : phase + f * 0.25 * rate;
            g.rotations.push_back(quat_identity());
            g.rotations.push_back(quat_axis_angle(vec3(1, 0, 0), 0.6 * det::sin(t)));
            g.rotations.push_back(quat_axis_angle(vec3(1, 0, 0), 0.4 + 0.3 * det::sin(t + 1.0)));
            for (int j = 0; j < 3; ++j) g.translations.push_back(j == 0 ? vec3(0.0f, 0.9f, 0.0f) : vec3(0.0f, -0.4f, 0.0f));
            g.contacts.push_back(0);
        }
    g.nodes = {{0, 0}, {0, from}, {0, frames - 1}, {1, 0}, {1, to}, {1, frames - 1}};
    auto clip_edge = [&](int a, int b) {
        GraphEdge e;
        e.from = a, e.to = b, e.kind = GraphEdgeKind::clip;
        e.frames = g.nodes[static_cast<size_t>(b)].frame - g.nodes[static_cast<size_t>(a)].frame;
        g.edges.push_back(e);
    };
    clip_edge(0, 1), clip_edge(1, 2), clip_edge(3, 4), clip_edge(4, 5);
    GraphEdge t;
    t.from = 1, t.to = 4, t.kind = GraphEdgeKind::transition, t.frames = k;
    g.edges.push_back(t);
    index_edges(g);
    return g;
}

const GraphEdge& transition_of(const MotionGraph& g) {
    for (const GraphEdge& e : g.edges)
        if (e.kind == GraphEdgeKind::transition) return e;
    FAIL("no transition");
    return g.edges.front();
}
const GraphEdge& clip_edge_of(const MotionGraph& g) {
    for (const GraphEdge& e : g.edges)
        if (e.kind == GraphEdgeKind::clip) return e;
    FAIL("no clip edge");
    return g.edges.front();
}

// Σ over non-root joints of 1 − |q_a·q_b| between window time ta of clip 0's
// window and tb of clip 1's (frames interpolated as the blend samples them).
double mismatch(const MotionGraph& g, int first_a, double ta, int first_b, double tb) {
    auto joint = [&](int first, double time, size_t j) {
        const int whole = static_cast<int>(time);
        const float u = static_cast<float>(time - whole);
        const quat q0 = g.rotations[static_cast<size_t>(first + whole) * 3 + j];
        return u > 0.0f ? quat_slerp(q0, g.rotations[static_cast<size_t>(first + whole + 1) * 3 + j], u) : q0;
    };
    double d = 0.0;
    for (size_t j = 1; j < 3; ++j) {
        const quat a = joint(first_a, ta, j), b = joint(first_b, tb, j);
        d += 1.0 - std::fabs(static_cast<double>(a.w) * b.w + static_cast<double>(a.x) * b.x +
                             static_cast<double>(a.y) * b.y + static_cast<double>(a.z) * b.z);
    }
    return d;
}
}  // namespace

TEST_CASE("transition_time_warp: generated swings, fixed ends, monotonic, banded, closer pairs than the plain blend",
          "[graph][warp]") {
    std::uint32_t seed = 2024u;
    auto next = [&] { seed = seed * 1664525u + 1013904223u; return static_cast<double>(seed >> 8) / 16777216.0; };
    double warped_sum = 0.0, plain_sum = 0.0;
    int cases = 0;
    for (int c = 0; c < 400; ++c) {
        const int k = 4 + static_cast<int>(next() * 13.0);  // 4 … 16
        const double rate = 0.6 + next();
        const double phase = next() * 6.283185307179586;
        const int from = 5 + static_cast<int>(next() * 20.0), to = k + 5 + static_cast<int>(next() * 20.0);
        const MotionGraph g = swing_graph(k, rate, phase, from, to);
        const GraphEdge& e = transition_of(g);
        std::vector<float> warp(2 * static_cast<size_t>(k), -1.0f);
        transition_time_warp(g, e, warp);
        INFO("case " << c << ": k " << k << " rate " << rate << " phase " << phase);
        CHECK(warp[0] == 0.0f);
        CHECK(warp[static_cast<size_t>(k)] == 0.0f);
        CHECK(warp[static_cast<size_t>(k - 1)] == static_cast<float>(k - 1));
        CHECK(warp[static_cast<size_t>(2 * k - 1)] == static_cast<float>(k - 1));
        const double band = std::max(1, static_cast<int>(kWarpBandFraction * k));
        for (int p = 1; p < k; ++p) {
            CHECK(warp[static_cast<size_t>(p)] >= warp[static_cast<size_t>(p - 1)]);
            CHECK(warp[static_cast<size_t>(k + p)] >= warp[static_cast<size_t>(k + p - 1)]);
            CHECK(std::fabs(warp[static_cast<size_t>(p)] - warp[static_cast<size_t>(k + p)]) <= band + 1e-5);
        }
        double warped_cost = 0.0, diagonal_cost = 0.0;
        transition_warp_costs(g, e, warped_cost, diagonal_cost);
        CHECK(warped_cost <= diagonal_cost + 1e-12);
        const int first_a = from, first_b = 60 + to - k;
        for (int p = 0; p < k; ++p) {
            warped_sum += mismatch(g, first_a, warp[static_cast<size_t>(p)], first_b, warp[static_cast<size_t>(k + p)]);
            plain_sum += mismatch(g, first_a, p, first_b, p);
        }
        ++cases;
    }
    INFO("pose mismatch summed over the blends: warped " << warped_sum << ", plain " << plain_sum);
    CHECK(cases == 400);
    CHECK(warped_sum < 0.8 * plain_sum);
}

TEST_CASE("transition_time_warp: identity for identical windows, clip edges, short windows and a wrong size",
          "[graph][warp]") {
    // The same clip at the same rate and phase, entered at the same frame: the identity, exactly.
    const MotionGraph same = swing_graph(10, 1.0, 0.0, 12, 22);
    std::vector<float> warp(20, -1.0f);
    transition_time_warp(same, transition_of(same), warp);
    for (int p = 0; p < 10; ++p) {
        CHECK(warp[static_cast<size_t>(p)] == static_cast<float>(p));
        CHECK(warp[static_cast<size_t>(10 + p)] == static_cast<float>(p));
    }
    // Identity warp: the blend is bit for bit the plain one.
    std::vector<quat> r0(3), r1(3);
    std::vector<vec3> t0(3), t1(3);
    for (int p = 0; p < 10; ++p) {
        graph_transition_pose(same, transition_of(same), p, PlanarTransform{}, r0, t0);
        graph_transition_pose(same, transition_of(same), p, PlanarTransform{}, r1, t1, warp);
        for (size_t j = 0; j < 3; ++j) {
            CHECK((r0[j].w == r1[j].w && r0[j].x == r1[j].x && r0[j].y == r1[j].y && r0[j].z == r1[j].z));
            CHECK((t0[j].x == t1[j].x && t0[j].y == t1[j].y && t0[j].z == t1[j].z));
        }
    }
    const MotionGraph g = swing_graph(10, 1.4, 1.0, 12, 22);
    transition_time_warp(g, clip_edge_of(g), warp);  // a clip edge
    for (int p = 0; p < 10; ++p) CHECK(warp[static_cast<size_t>(p)] == static_cast<float>(p));
    std::vector<float> wrong(7, -1.0f);
    transition_time_warp(g, transition_of(g), wrong);
    for (float w : wrong) CHECK(w == -1.0f);
    const MotionGraph short_window = swing_graph(2, 1.4, 1.0, 12, 22);
    std::vector<float> two(4, -1.0f);
    transition_time_warp(short_window, transition_of(short_window), two);
    CHECK((two[0] == 0.0f && two[1] == 1.0f && two[2] == 0.0f && two[3] == 1.0f));
    // A window past kMaxWarpWindowFrames (a file may claim any): the identity, no k² table.
    const int long_k = kMaxWarpWindowFrames + 6;
    const MotionGraph long_window = swing_graph(long_k, 1.4, 1.0, 12, long_k + 10, 3 * long_k);
    std::vector<float> long_warp(2 * static_cast<size_t>(long_k), -1.0f);
    transition_time_warp(long_window, transition_of(long_window), long_warp);
    for (int p = 0; p < long_k; ++p) {
        CHECK(long_warp[static_cast<size_t>(p)] == static_cast<float>(p));
        CHECK(long_warp[static_cast<size_t>(long_k + p)] == static_cast<float>(p));
    }
    CHECK_FALSE(transition_warps_affordable(long_window));
    CHECK(transition_warps_affordable(same));
    // Too many transitions × joints for the work budget: none warped. (Only
    // counted, so the copies and extra joints need no frames: 1.1 × the budget.)
    MotionGraph crowded = same;
    crowded.edges.insert(crowded.edges.end(), 999, transition_of(same));
    const double per_joint = 1000.0 * 10.0 * (2.0 * 2.0 + 1.0);  // transitions × k × (2·band + 1)
    crowded.skeleton.parents.resize(static_cast<size_t>(1.1 * kMaxWarpWork / per_joint), 0);
    CHECK_FALSE(transition_warps_affordable(crowded));
    crowded.skeleton.parents.resize(static_cast<size_t>(0.9 * kMaxWarpWork / per_joint), 0);
    CHECK(transition_warps_affordable(crowded));
}
