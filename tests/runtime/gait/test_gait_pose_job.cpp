// GaitPoseJob (runtime/gait/gait.hpp): the pose of a gait state, as a job.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "runtime/gait/gait.hpp"
#include "runtime/gait/puppet.hpp"
#include "runtime/math/det_math.hpp"
#include "runtime/sim/simulation.hpp"
#include "tests/alloc_counter.hpp"
#include "tests/job_sentinel.hpp"
#include "tests/seeded_random.hpp"

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

// The knee follows the ankle smoothly wherever a swing can take it: below the
// hip, beside it, ahead of it and behind it at hip height (a foot swung onto a
// high step or lifted off one). A fixed forward pole flipped the knee through
// 180° in one tick as the ankle passed hip height ahead of the hip, and turned
// it fast about a leg pointing sideways (sweep cases 7-0901, 2-0186).
// Generated walks of the right ankle in 2 mm steps, each step's thigh and shin
// turn held to a multiple of the turn the hip→ankle line itself makes.
TEST_CASE("GaitPoseJob: the knee turns smoothly with the ankle anywhere a swing takes it", "[gait][job]") {
    StandingPuppet puppet;
    test::SentinelPose out(kJoints);
    const GaitPoseJob job = puppet.job(out.spans());
    REQUIRE(job.run());
    const vec3 hip = out.model_positions[kThighR];
    const float reach = puppet.rig.thigh + puppet.rig.shin;
    test::SeededRandom rng{2001};
    const auto random_direction = [&] {
        // Anywhere below the hip up to 12° above its height, any heading.
        const double yaw = rng.uniform(-det::kPi, det::kPi);
        const double elevation = rng.uniform(-0.5 * det::kPi, 0.21);
        return vec3(static_cast<float>(std::cos(elevation) * std::sin(yaw)), static_cast<float>(std::sin(elevation)),
                    static_cast<float>(std::cos(elevation) * std::cos(yaw)));
    };
    double worst_ratio = 0.0;
    int steps = 0;
    for (int walk = 0; walk < 300; ++walk) {
        const float distance = static_cast<float>(rng.uniform(0.35, 0.95)) * reach;
        vec3 direction = random_direction();
        const vec3 heading_to = random_direction();
        quat thigh{}, shin{};
        for (int step = 0; step <= 120; ++step) {
            // Turn the direction toward another one, 2 mm of ankle travel a step.
            if (step > 0) direction = normalize(direction + (heading_to - direction * dot(heading_to, direction)) * (0.002f / distance));
            if (direction.y > 0.21f) break;
            puppet.gait.feet[1].ankle = hip + direction * distance;
            REQUIRE(puppet.job(out.spans()).run());
            if (step > 0) {
                const double line_turn = 0.002 / distance;
                const double turn = std::max(quat_angle_between(thigh, out.model_rotations[kThighR]),
                                             quat_angle_between(shin, out.model_rotations[kShinR]));
                worst_ratio = std::max(worst_ratio, turn / line_turn);
                ++steps;
            }
            thigh = out.model_rotations[kThighR];
            shin = out.model_rotations[kShinR];
        }
    }
    INFO("steps " << steps << ", worst knee turn per hip-ankle line turn " << worst_ratio);
    CHECK(steps > 20000);
    CHECK(worst_ratio < 4.0);
}
