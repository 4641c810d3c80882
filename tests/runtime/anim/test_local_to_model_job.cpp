// LocalToModelJob (runtime/anim/skeleton.hpp): forward kinematics as a job.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
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

namespace {
// Raw mt19937 words (the engine's sequence is fixed by the standard; the
// distributions are not, so none is used).
float unit_float(std::mt19937& rng) { return static_cast<float>(rng() >> 8) * (1.0f / 16777216.0f); }

// A coordinate from the whole float range: ordinary values most of the time,
// then zeros of both signs, denormals, huge values (products overflow), infinities and NaN.
float any_coordinate(std::mt19937& rng) {
    const std::uint32_t kind = rng() % 16;
    const float u = unit_float(rng) * 2.0f - 1.0f;
    switch (kind) {
        case 0: return 0.0f;
        case 1: return -0.0f;
        case 2: return u * 1e-39f;  // denormal
        case 3: return u * 3e38f;
        case 4: return (rng() & 1) ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity();
        case 5: return std::numeric_limits<float>::quiet_NaN();
        case 6: return u * 1e6f;
        default: return u;
    }
}

std::uint32_t bits(float f) {
    std::uint32_t b;
    std::memcpy(&b, &f, sizeof b);
    return b;
}
}  // namespace

// Every non-NaN float must have the same bits on both paths (zeros' signs,
// denormals, infinities included). Two NaNs count as equal whatever their sign
// and payload: IEEE 754 leaves those open, x86 returns the first operand's NaN and
// a compiler may swap the operands of a commutative + or * differently in the
// scalar and the vector code. The tick's input is integers and its poses stay
// finite, so no golden or state hash ever holds a NaN.
TEST_CASE("LocalToModelJob::run gives run_reference's bits on random skeletons and poses", "[skeleton][job][simd]") {
    std::mt19937 rng(20);
    int poses = 0, joints_compared = 0, mismatches = 0, nan_pairs = 0;
    for (int skeleton_case = 0; skeleton_case < 200; ++skeleton_case) {
        // 1 to 300 joints (past kLocalToModelBatchedJoints the reference loop runs);
        // parents: a chain, a bush, or random earlier joints with a few extra roots.
        const int n = 1 + static_cast<int>(rng() % (skeleton_case % 10 == 0 ? 300u : 70u));
        std::vector<int> parents(static_cast<size_t>(n));
        const std::uint32_t shape = rng() % 3;
        for (int i = 0; i < n; ++i) {
            int p = kNoParent;
            if (i > 0 && rng() % 23 != 0) p = shape == 0 ? i - 1 : (shape == 1 ? static_cast<int>(rng() % 3u) % i : static_cast<int>(rng() % static_cast<std::uint32_t>(i)));
            parents[static_cast<size_t>(i)] = p;
        }
        for (int pose_case = 0; pose_case < 10; ++pose_case, ++poses) {
            // Half the poses are ordinary (unit quaternions, offsets under a metre),
            // half draw every coordinate from the whole range, degenerate ones included.
            const bool wild = pose_case % 2 == 1;
            std::vector<quat> lr(static_cast<size_t>(n));
            std::vector<vec3> lt(static_cast<size_t>(n));
            for (int i = 0; i < n; ++i) {
                const size_t k = static_cast<size_t>(i);
                if (wild) {
                    lr[k] = quat(any_coordinate(rng), any_coordinate(rng), any_coordinate(rng), any_coordinate(rng));
                    lt[k] = vec3(any_coordinate(rng), any_coordinate(rng), any_coordinate(rng));
                } else {
                    lr[k] = quat_normalize(quat(unit_float(rng) - 0.5f, unit_float(rng) - 0.5f, unit_float(rng) - 0.5f, unit_float(rng) - 0.5f));
                    lt[k] = vec3(unit_float(rng) - 0.5f, unit_float(rng) - 0.5f, unit_float(rng) - 0.5f);
                }
            }
            std::vector<quat> mr_fast(static_cast<size_t>(n)), mr_ref(static_cast<size_t>(n));
            std::vector<vec3> mp_fast(static_cast<size_t>(n)), mp_ref(static_cast<size_t>(n));
            REQUIRE(LocalToModelJob{parents, {lr, lt}, {mr_fast, mp_fast}}.run());
            REQUIRE(LocalToModelJob{parents, {lr, lt}, {mr_ref, mp_ref}}.run_reference());
            for (size_t k = 0; k < static_cast<size_t>(n); ++k, ++joints_compared) {
                const float a[7] = {mr_fast[k].w, mr_fast[k].x, mr_fast[k].y, mr_fast[k].z, mp_fast[k].x, mp_fast[k].y, mp_fast[k].z};
                const float b[7] = {mr_ref[k].w, mr_ref[k].x, mr_ref[k].y, mr_ref[k].z, mp_ref[k].x, mp_ref[k].y, mp_ref[k].z};
                for (int c = 0; c < 7; ++c)
                    if (std::isnan(a[c]) && std::isnan(b[c])) {
                        ++nan_pairs;  // see the note above: a NaN's sign and payload are not compared
                    } else if (bits(a[c]) != bits(b[c])) {
                        if (mismatches++ < 5) FAIL_CHECK("skeleton case " << skeleton_case << ", pose " << pose_case << ", joint " << k << ", component " << c << ": " << a[c] << " vs " << b[c]);
                    }
            }
        }
    }
    CHECK(poses == 2000);
    CHECK(joints_compared > 50000);
    CHECK(mismatches == 0);
    CHECK(nan_pairs > 0);  // the wild poses did reach NaN
}
