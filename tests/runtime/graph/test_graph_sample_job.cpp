// GraphSampleJob (runtime/graph/graph_sample.hpp): a motion graph's pose at a
// point along an edge, as a job.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "runtime/graph/graph_path.hpp"
#include "runtime/graph/graph_sample.hpp"
#include "tests/alloc_counter.hpp"
#include "tests/job_sentinel.hpp"
#include "tests/runtime/graph/small_graph.hpp"

using namespace marionette;

namespace {
constexpr std::int32_t kClipEdge = 0;        // a0 → a4: frames 0 … 3 of clip "a"
constexpr std::size_t kJoints = 2;

// Every joint of two local poses alike (rotations within 1e-6 rad, translations 1e-5 graph units).
void check_same_pose(const std::vector<quat>& r, const std::vector<vec3>& t, const std::vector<quat>& expected_r,
                     const std::vector<vec3>& expected_t) {
    for (std::size_t j = 0; j < kJoints; ++j) {
        CHECK(quat_angle_between(r[j], expected_r[j]) < 1e-6);
        CHECK(glm::length(t[j] - expected_t[j]) < 1e-5f);
    }
}
}  // namespace

TEST_CASE("GraphSampleJob: bad inputs fail validate() and run() writes nothing", "[graph][job]") {
    const MotionGraph graph = test::small_graph();
    REQUIRE(validate_motion_graph(graph).ok());
    test::SentinelPose out(kJoints), scratch(kJoints);
    const GraphSampleJob valid{&graph, kClipEdge, 1.5f, PlanarTransform{}, scratch.local(), out.local(), {}};
    const auto check_refused = [&](const GraphSampleJob& job) {
        CHECK_FALSE(job.validate());
        CHECK_FALSE(job.run());
        CHECK(out.untouched());
        CHECK(scratch.untouched());
    };
    SECTION("no graph") {
        GraphSampleJob job = valid;
        job.graph = nullptr;
        check_refused(job);
    }
    SECTION("an edge not in the graph") {
        GraphSampleJob job = valid;
        job.edge = -1;
        check_refused(job);
        job.edge = static_cast<std::int32_t>(graph.edges.size());
        check_refused(job);
    }
    SECTION("a position off the edge") {
        GraphSampleJob job = valid;
        job.edge_position = -0.25f;
        check_refused(job);
        job.edge_position = static_cast<float>(graph.edges[kClipEdge].frames) + 0.5f;
        check_refused(job);
        job.edge_position = NAN;
        check_refused(job);
    }
    SECTION("spans not of the graph's joint count") {
        test::SentinelPose longer(kJoints + 1);
        GraphSampleJob job = valid;
        job.output.rotations = longer.local_rotations;
        check_refused(job);
        job = valid;
        job.output.translations = {};
        check_refused(job);
        job = valid;
        job.scratch.rotations = {};
        check_refused(job);
        job = valid;
        job.scratch.translations = longer.local_translations;
        check_refused(job);
        CHECK(longer.untouched());
    }
    SECTION("valid inputs run and write every joint") {
        CHECK(valid.validate());
        CHECK(valid.run());
        for (std::size_t j = 0; j < kJoints; ++j) {
            CHECK(out.local_rotations[j] != test::kSentinelRotation);
            CHECK(out.local_translations[j] != test::kSentinelPosition);
        }
    }
}

TEST_CASE("GraphSampleJob interpolates between an edge's frames and ends on its target node", "[graph][job]") {
    const MotionGraph graph = test::small_graph();
    std::vector<quat> r(kJoints), scratch_r(kJoints), frame_r(kJoints);
    std::vector<vec3> t(kJoints), scratch_t(kJoints), frame_t(kJoints);
    const PlanarTransform world{0.5, 2.0, -1.0};
    GraphSampleJob job{&graph, kClipEdge, 2.0f, world, {scratch_r, scratch_t}, {r, t}, {}};
    // On a frame: that database frame, placed in the world.
    REQUIRE(job.run());
    graph_frame_pose(graph, 2, world, frame_r, frame_t);
    check_same_pose(r, t, frame_r, frame_t);
    // Halfway: the root's translation halfway between frames 2 and 3 (0.1 m apart along x).
    job.edge_position = 2.5f;
    REQUIRE(job.run());
    const vec3 halfway = apply_planar(world, vec3(0.25f, 1.0f, 0.0f));
    CHECK(t[0].x == Approx(halfway.x).margin(1e-5));
    CHECK(t[0].z == Approx(halfway.z).margin(1e-5));
    // At the edge's end: the target node's frame (a4 = global frame 4).
    job.edge_position = static_cast<float>(graph.edges[kClipEdge].frames);
    REQUIRE(job.run());
    graph_frame_pose(graph, 4, world, frame_r, frame_t);
    check_same_pose(r, t, frame_r, frame_t);
}

TEST_CASE("GraphSampleJob::run never allocates", "[graph][job]") {
    const MotionGraph graph = test::small_graph();
    test::SentinelPose out(kJoints), scratch(kJoints);
    GraphSampleJob job{&graph, kClipEdge, 0.0f, PlanarTransform{}, scratch.local(), out.local(), {}};
    int refused = 0;
    const std::uint64_t before = test::allocation_count();
    for (int i = 0; i < 100; ++i) {
        job.edge_position = 0.03f * static_cast<float>(i);
        if (!job.run()) ++refused;
    }
    CHECK(test::allocation_count() == before);
    CHECK(refused == 0);
}
