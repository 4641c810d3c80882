// LocalToModelJob (runtime/anim/skeleton.hpp): forward kinematics as a job.
#include <catch2/catch.hpp>

#include <vector>

#include "runtime/anim/skeleton.hpp"
#include "tests/alloc_counter.hpp"
#include "tests/job_sentinel.hpp"
#include "tests/runtime/anim/chain_skeleton.hpp"

using namespace marionette;

TEST_CASE("LocalToModelJob: bad inputs fail validate() and run() writes nothing", "[skeleton][job]") {
    const Skeleton s = test::chain();
    const Pose pose = rest_pose(s);
    const LocalPoseInput local{pose.local_rotations, pose.local_translations};
    test::SentinelPose out(3);
    const auto check_refused = [&](const LocalToModelJob& job) {
        CHECK_FALSE(job.validate());
        CHECK_FALSE(job.run());
        CHECK(out.untouched());
    };
    SECTION("model spans shorter than the skeleton") {
        check_refused({s.parents, local, {std::span<quat>(out.model_rotations).first(2), out.model_positions}});
        check_refused({s.parents, local, {out.model_rotations, std::span<vec3>(out.model_positions).first(2)}});
    }
    SECTION("no model spans at all (null data)") {
        check_refused({s.parents, local, {std::span<quat>(), std::span<vec3>()}});
    }
    SECTION("local spans not of the skeleton's size") {
        check_refused({s.parents, {std::span<const quat>(pose.local_rotations).first(2), pose.local_translations}, out.model()});
        check_refused({s.parents, {pose.local_rotations, std::span<const vec3>()}, out.model()});
    }
    SECTION("parents not before their children") {
        const std::vector<int> cyclic = {kNoParent, 2, 1};
        check_refused({cyclic, local, out.model()});
        const std::vector<int> own_parent = {kNoParent, 1, 1};
        check_refused({own_parent, local, out.model()});
        const std::vector<int> below_no_parent = {kNoParent, -2, 1};
        check_refused({below_no_parent, local, out.model()});
    }
    SECTION("the checks this job always had") {
        std::vector<quat> mr(2);
        std::vector<vec3> mp(3);
        CHECK_FALSE(LocalToModelJob{s.parents, local, {mr, mp}}.validate());
        std::vector<int> cyclic = {kNoParent, 2, 1};
        std::vector<quat> mr3(3);
        CHECK_FALSE(LocalToModelJob{cyclic, local, {mr3, mp}}.validate());
    }
    SECTION("valid inputs run and write every joint") {
        const LocalToModelJob job{s.parents, local, out.model()};
        CHECK(job.validate());
        CHECK(job.run());
        CHECK(out.model_positions[2] == vec3(1, 5, 0));
    }
}

TEST_CASE("forward kinematics of a bent chain", "[skeleton][job]") {
    const Skeleton s = test::chain();
    REQUIRE(validate_skeleton(s).ok());
    Pose pose = rest_pose(s);
    pose.local_rotations[1] = quat_axis_angle(vec3(0, 0, 1), det::kHalfPi);
    std::vector<quat> mr(3);
    std::vector<vec3> mp(3);
    LocalToModelJob job{s.parents, {pose.local_rotations, pose.local_translations}, {mr, mp}};
    REQUIRE(job.validate());
    REQUIRE(job.run());
    // root at (1,0,0); mid 2 up; tip 3 along mid's rotated +Y, which is −X.
    CHECK(mp[0].x == Approx(1));
    CHECK(mp[1].y == Approx(2));
    CHECK(mp[2].x == Approx(-2).margin(1e-6));
    CHECK(mp[2].y == Approx(2).margin(1e-6));
}

TEST_CASE("LocalToModelJob writes only the skeleton's joints into longer model spans", "[skeleton][job]") {
    const Skeleton s = test::chain();
    const Pose pose = rest_pose(s);
    test::SentinelPose out(5);
    REQUIRE(LocalToModelJob{s.parents, {pose.local_rotations, pose.local_translations}, out.model()}.run());
    CHECK(out.model_positions[2] == vec3(1, 5, 0));
    CHECK(out.model_positions[3] == test::kSentinelPosition);
    CHECK(out.model_rotations[4] == test::kSentinelRotation);
}

TEST_CASE("LocalToModelJob::run never allocates", "[skeleton][job]") {
    const Skeleton s = test::chain();
    const Pose pose = rest_pose(s);
    std::vector<quat> mr(3);
    std::vector<vec3> mp(3);
    const LocalToModelJob job{s.parents, {pose.local_rotations, pose.local_translations}, {mr, mp}};
    int refused = 0;
    const std::uint64_t before = test::allocation_count();
    for (int i = 0; i < 100; ++i)
        if (!job.run()) ++refused;
    CHECK(test::allocation_count() == before);
    CHECK(refused == 0);
}
