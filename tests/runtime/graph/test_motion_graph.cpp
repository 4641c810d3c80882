// Run-time motion-graph pieces: closed-form alignment, path search, the .mgraph
// format, transition blending.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "runtime/graph/graph_path.hpp"
#include "runtime/errors/import_error.hpp"
#include "runtime/graph/motion_graph.hpp"
#include "runtime/math/planar_alignment.hpp"
#include "tests/runtime/graph/small_graph.hpp"

using namespace marionette;
using marionette::test::small_graph;


TEST_CASE("closed-form planar alignment matches a brute-force search over angles", "[graph][alignment]") {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (int trial = 0; trial < 20; ++trial) {
        std::vector<vec3> a(25), b(25);
        std::vector<float> w(25);
        const PlanarTransform truth{u(rng) * 3.0, u(rng) * 5.0, u(rng) * 5.0};
        for (size_t i = 0; i < a.size(); ++i) {
            b[i] = vec3(u(rng), u(rng) + 1.0f, u(rng));
            a[i] = apply_planar(truth, b[i]) + 0.05f * vec3(u(rng), u(rng), u(rng));
            w[i] = 0.5f + 0.5f * (u(rng) + 1.0f);
        }
        const PlanarTransform t = align_point_clouds(a, b, w);
        const double closed = planar_cloud_distance(a, b, w, t);
        // Brute force: every 0.05° with the optimal translation for that angle (weighted centroids).
        double best = 1e300, best_angle = 0.0;
        for (int step = 0; step < 7200; ++step) {
            const double angle = -det::kPi + step * (det::kTwoPi / 7200);
            PlanarTransform r{angle, 0.0, 0.0};
            double sw = 0, ax = 0, az = 0, bx = 0, bz = 0;
            for (size_t i = 0; i < a.size(); ++i) {
                const vec3 rb = apply_planar(r, b[i]);
                sw += w[i], ax += w[i] * a[i].x, az += w[i] * a[i].z, bx += w[i] * rb.x, bz += w[i] * rb.z;
            }
            r.dx = (ax - bx) / sw, r.dz = (az - bz) / sw;
            const double d = planar_cloud_distance(a, b, w, r);
            if (d < best) best = d, best_angle = angle;
        }
        CHECK(closed <= best + 1e-6);
        CHECK(std::abs(det::wrap_angle(t.angle - best_angle)) < 0.002);
        CHECK(std::abs(det::wrap_angle(t.angle - truth.angle)) < 0.05);
    }
}

TEST_CASE("alignment composes and places points as quat_axis_angle rotates them", "[graph][alignment]") {
    const PlanarTransform t{0.7, 1.5, -2.0};
    const vec3 p(0.3f, 1.0f, -0.8f);
    const vec3 q = apply_planar(t, p);
    const vec3 r = quat_rotate(planar_rotation(t), p) + vec3(1.5f, 0.0f, -2.0f);
    CHECK(glm::length(q - r) < 1e-5f);
    const PlanarTransform s{-0.2, 0.4, 0.1};
    const vec3 two = apply_planar(t, apply_planar(s, p));
    CHECK(glm::length(apply_planar(compose_planar(t, s), p) - two) < 1e-5f);
}

TEST_CASE("path search reaches a label and a clip frame, never allocating", "[graph][path]") {
    MotionGraph g = small_graph();
    g.edges.erase(g.edges.begin() + g.edge_begin[4] + 2);  // drop b4 → c9: c becomes unreachable
    index_edges(g);
    REQUIRE(validate_motion_graph(g).ok());
    GraphPathSearch search(g, 1.0);
    search.add_label_goal(g.label_index("run"));  // clip b
    REQUIRE(search.run(0));                        // from a0
    const auto path = search.path();
    REQUIRE(!path.empty());
    const GraphNode& goal = g.nodes[static_cast<size_t>(search.goal_node())];
    CHECK(g.clips[static_cast<size_t>(goal.clip)].name == "b");
    // a0 →(4 frames) a4 →(transition, 2 frames, cost 0.1) b4: 0.6 s + 0.1.
    CHECK(search.cost() == Approx(0.6 + 0.1));
    CHECK(g.edges[static_cast<size_t>(path.back())].kind == GraphEdgeKind::transition);

    search.clear_goals();
    REQUIRE(search.add_frame_goal(1, 7));  // b7 lies on b4→b9
    REQUIRE(search.run(0));
    CHECK(search.goal_frames_after() == 3);
    CHECK(search.cost() == Approx(0.6 + 0.1 + 0.3));
    search.clear_goals();
    REQUIRE(search.add_frame_goal(2, 3));  // c3 is on the clip edge c0 → c9 …
    CHECK_FALSE(search.run(0));            // … but nothing leads into c any more
}

TEST_CASE("transitions blend from the source pose to the aligned target pose", "[graph][transition]") {
    MotionGraph g = small_graph();
    const GraphEdge e = g.edges[static_cast<size_t>(g.edge_begin[1]) + 1];  // a4 → a9, then a4 → b4
    REQUIRE(e.kind == GraphEdgeKind::transition);
    CHECK(transition_weight(-1, 2) == Approx(1.0f));
    CHECK(transition_weight(g.window_frames - 1, g.window_frames) == Approx(0.0f).margin(1e-7));
    std::vector<quat> r(2);
    std::vector<vec3> t(2);
    graph_transition_pose(g, e, g.window_frames - 1, PlanarTransform{}, r, t);
    // The last blend frame is exactly the target's frame b.frame − 1 (b3).
    std::vector<quat> rb(2);
    std::vector<vec3> tb(2);
    graph_frame_pose(g, 10 + 3, PlanarTransform{}, rb, tb);
    CHECK(glm::length(t[0] - tb[0]) < 1e-6f);
    CHECK(quat_angle_between(r[0], rb[0]) < 1e-3);
}

TEST_CASE("the .mgraph format round-trips and rejects damage with the byte", "[graph][format]") {
    MotionGraph g = small_graph();
    g.source_hash = 0x1234abcd5678ef00ull;
    g.source_clips = {"x.bvh"};
    g.stats.candidates = 3;
    const std::vector<std::uint8_t> bytes = serialize_motion_graph(g);
    const MotionGraph back = deserialize_motion_graph(bytes, "g.mgraph");
    CHECK(back.source_hash == g.source_hash);
    CHECK(motion_graph_source_hash(bytes, "g.mgraph") == g.source_hash);
    CHECK(back.nodes.size() == g.nodes.size());
    CHECK(back.edges.size() == g.edges.size());
    CHECK(back.edge_begin == g.edge_begin);
    CHECK(back.clips[2].name == "c");
    CHECK(back.stats.candidates == 3);
    CHECK(serialize_motion_graph(back) == bytes);

    std::vector<std::uint8_t> bad = bytes;
    bad[bad.size() / 2] ^= 0x40;
    CHECK_THROWS_WITH(deserialize_motion_graph(bad, "g.mgraph"), Catch::Contains("checksum"));
    std::vector<std::uint8_t> cut(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(bytes.size() - 7));
    CHECK_THROWS_WITH(deserialize_motion_graph(cut, "g.mgraph"), Catch::Contains("truncated"));
    std::vector<std::uint8_t> version = bytes;
    version[8] = 9;
    CHECK_THROWS_WITH(deserialize_motion_graph(version, "g.mgraph"), Catch::Contains("version 9"));
    CHECK_THROWS_WITH(deserialize_motion_graph(std::vector<std::uint8_t>{1, 2, 3}, "g.mgraph"),
                      Catch::Contains("g.mgraph: at byte 0"));
}
