// GaitPoseJob (runtime/gait/gait.hpp): the pose of a gait state, as a job.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "runtime/gait/gait.hpp"
#include "runtime/gait/puppet.hpp"
#include "runtime/sim/simulation.hpp"
#include "tests/alloc_counter.hpp"
#include "tests/job_sentinel.hpp"

using namespace marionette;

namespace {
// The puppet standing at the origin on flat ground, as a Simulation starts it.
struct StandingPuppet {
    SimConfig config;
    Skeleton skeleton = make_puppet_skeleton(config);
    GaitRig rig = make_gait_rig(config);
    Terrain flat;
    GaitState gait = initial_gait_state(config, rig, flat, vec3(0.0f), 0.0f);

    GaitPoseJob job(PoseSpans pose) const {
        return {&gait, &rig, &config, 0.0f, 0.0f, skeleton.parents, skeleton.rest_offsets, pose};
    }
};
constexpr std::size_t kJoints = static_cast<std::size_t>(kPuppetJointCount);
}  // namespace

TEST_CASE("GaitPoseJob: bad inputs fail validate() and run() writes nothing", "[gait][job]") {
    StandingPuppet puppet;
    test::SentinelPose out(kJoints);
    const GaitPoseJob valid = puppet.job(out.spans());
    const auto check_refused = [&](const GaitPoseJob& job) {
        CHECK_FALSE(job.validate());
        CHECK_FALSE(job.run());
        CHECK(out.untouched());
    };
    SECTION("null state, rig or config") {
        GaitPoseJob job = valid;
        job.gait = nullptr;
        check_refused(job);
        job = valid;
        job.rig = nullptr;
        check_refused(job);
        job = valid;
        job.config = nullptr;
        check_refused(job);
    }
    SECTION("skeleton spans not of the puppet's joint count") {
        GaitPoseJob job = valid;
        job.parents = job.parents.first(kJoints - 1);
        check_refused(job);
        job = valid;
        job.rest_offsets = {};
        check_refused(job);
    }
    SECTION("pose spans not of the puppet's joint count") {
        test::SentinelPose longer(kJoints + 1);
        for (int span = 0; span < 4; ++span) {
            PoseSpans p = out.spans();
            if (span == 0) p.local_rotations = longer.local_rotations;
            if (span == 1) p.local_translations = longer.local_translations;
            if (span == 2) p.model_rotations = longer.model_rotations;
            if (span == 3) p.model_positions = std::span<vec3>();
            GaitPoseJob job = valid;
            job.pose = p;
            check_refused(job);
        }
        CHECK(longer.untouched());
    }
    SECTION("parents not before their children") {
        std::vector<int> parents = puppet.skeleton.parents;
        parents[kShinL] = kFootL;
        GaitPoseJob job = valid;
        job.parents = parents;
        check_refused(job);
    }
    SECTION("bone lengths the IK cannot use") {
        StandingPuppet broken;
        broken.rig.shin = 0.0f;
        check_refused(broken.job(out.spans()));
        broken = StandingPuppet{};
        broken.rig.forearm = NAN;
        check_refused(broken.job(out.spans()));
    }
    SECTION("a state that is not finite") {
        StandingPuppet broken;
        broken.gait.pelvis.y = NAN;
        check_refused(broken.job(out.spans()));
        broken = StandingPuppet{};
        broken.gait.feet[1].ankle.x = INFINITY;
        check_refused(broken.job(out.spans()));
        GaitPoseJob job = valid;
        job.heading = NAN;
        check_refused(job);
    }
    SECTION("valid inputs run and write every joint") {
        CHECK(valid.validate());
        CHECK(valid.run());
        for (std::size_t j = 0; j < kJoints; ++j) {
            CHECK(out.model_positions[j] != test::kSentinelPosition);
            CHECK(out.local_rotations[j] != test::kSentinelRotation);
        }
        CHECK(out.model_positions[kHead].y > 1.5f);
    }
}

TEST_CASE("GaitPoseJob poses the simulation's first tick bit for bit", "[gait][job]") {
    const StandingPuppet puppet;
    test::SentinelPose out(kJoints);
    REQUIRE(puppet.job(out.spans()).run());
    const Simulation sim(puppet.config);
    const PuppetState& s = sim.state();
    REQUIRE(s.joint_count == kPuppetJointCount);
    for (std::size_t j = 0; j < kJoints; ++j) {
        INFO("joint " << j);
        CHECK(out.local_rotations[j] == s.local_rotations[j]);
        CHECK(out.local_translations[j] == s.local_translations[j]);
        CHECK(out.model_rotations[j] == s.model_rotations[j]);
        CHECK(out.model_positions[j] == s.model_positions[j]);
    }
}

TEST_CASE("GaitPoseJob::run never allocates", "[gait][job]") {
    const StandingPuppet puppet;
    test::SentinelPose out(kJoints);
    const GaitPoseJob job = puppet.job(out.spans());
    int refused = 0;
    const std::uint64_t before = test::allocation_count();
    for (int i = 0; i < 100; ++i)
        if (!job.run()) ++refused;
    CHECK(test::allocation_count() == before);
    CHECK(refused == 0);
}
