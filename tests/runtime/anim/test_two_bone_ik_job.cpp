#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstring>
#include <span>

#include "runtime/anim/two_bone_ik.hpp"
#include "runtime/math/splitmix64.hpp"
#include "tests/alloc_counter.hpp"

using namespace marionette;

namespace {
float distance(vec3 a, vec3 b) {
    const vec3 d = a - b;
    return std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
}
float dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
bool finite(vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
TwoBoneIkJob leg(vec3 target) {
    TwoBoneIkJob in;
    in.root = vec3(0.09f, 0.9f, 0.0f);
    in.target = target;
    in.pole = vec3(0, 0, 1);
    in.upper_length = 0.44f;
    in.lower_length = 0.43f;
    return in;
}
// Runs a job the test expects to be valid and returns its result.
TwoBoneIkResult solve(TwoBoneIkJob in) {
    TwoBoneIkResult result;
    in.result = &result;
    REQUIRE(in.run());
    return result;
}
// The segment frames must carry the bones: −Y of each frame runs root → mid → end.
void check_frames(const TwoBoneIkJob& in, const TwoBoneIkResult& r) {
    CHECK(distance(in.root + quat_rotate(r.upper_rotation, vec3(0, -in.upper_length, 0)), r.mid) < 1e-5f);
    CHECK(distance(r.mid + quat_rotate(r.lower_rotation, vec3(0, -in.lower_length, 0)), r.end) < 1e-5f);
    CHECK(distance(quat_rotate(r.upper_rotation, vec3(1, 0, 0)), r.hinge_axis) < 1e-5f);
    CHECK(distance(quat_rotate(r.lower_rotation, vec3(1, 0, 0)), r.hinge_axis) < 1e-5f);
}
}  // namespace

TEST_CASE("TwoBoneIkJob: bad inputs fail validate() and run() writes nothing", "[ik][job]") {
    const TwoBoneIkResult sentinel{vec3(7.0f), vec3(8.0f), vec3(9.0f), quat(0.5f, 0.5f, 0.5f, 0.5f),
                                   quat(0.5f, -0.5f, 0.5f, -0.5f), 42.0f, true};
    const auto check_refused = [&](TwoBoneIkJob in) {
        TwoBoneIkResult result = sentinel;
        if (in.result) in.result = &result;
        CHECK_FALSE(in.validate());
        CHECK_FALSE(in.run());
        CHECK(result.mid == sentinel.mid);
        CHECK(result.end == sentinel.end);
        CHECK(result.hinge_axis == sentinel.hinge_axis);
        CHECK(result.upper_rotation == sentinel.upper_rotation);
        CHECK(result.lower_rotation == sentinel.lower_rotation);
        CHECK(result.reach == sentinel.reach);
        CHECK(result.reached == sentinel.reached);
    };
    TwoBoneIkResult unused;
    TwoBoneIkJob valid = leg(vec3(0.0f));
    valid.result = &unused;
    SECTION("no result to write") {
        TwoBoneIkJob in = valid;
        in.result = nullptr;
        check_refused(in);
    }
    SECTION("zero or negative bone lengths") {
        TwoBoneIkJob in = valid;
        in.upper_length = 0.0f;
        check_refused(in);
        in = valid;
        in.lower_length = -0.43f;
        check_refused(in);
    }
    SECTION("non-finite values") {
        TwoBoneIkJob in = leg(vec3(NAN, 0.0f, 0.0f));
        in.result = &unused;
        check_refused(in);
        in = valid;
        in.root.y = INFINITY;
        check_refused(in);
        in = valid;
        in.pole.z = NAN;
        check_refused(in);
        in = valid;
        in.upper_length = INFINITY;
        check_refused(in);
    }
    SECTION("soft reach outside (0, 1], negative fold margin") {
        TwoBoneIkJob in = valid;
        in.soft_reach_start = 0.0f;
        check_refused(in);
        in = valid;
        in.soft_reach_start = 1.5f;
        check_refused(in);
        in = valid;
        in.min_reach_margin = -1e-3f;
        check_refused(in);
    }
    SECTION("valid inputs run and write the result") {
        TwoBoneIkResult result = sentinel;
        TwoBoneIkJob in = valid;
        in.result = &result;
        CHECK(in.validate());
        CHECK(in.run());
        CHECK(result.reach != sentinel.reach);
        CHECK(finite(result.mid));
    }
}

TEST_CASE("TwoBoneIkJob::run never allocates", "[ik][job]") {
    TwoBoneIkResult result;
    TwoBoneIkJob in = leg(vec3(0.09f, 0.3f, 0.1f));
    in.result = &result;
    int refused = 0;
    const std::uint64_t before = test::allocation_count();
    for (int i = 0; i < 100; ++i) {
        in.target.z = 0.001f * static_cast<float>(i);
        if (!in.run()) ++refused;
    }
    CHECK(test::allocation_count() == before);
    CHECK(refused == 0);
}

TEST_CASE("two-bone IK reaches every reachable target within 0.1 mm with bone lengths kept", "[ik]") {
    int solved = 0;
    for (float x = -0.4f; x <= 0.4f; x += 0.1f)
        for (float y = 0.0f; y <= 0.8f; y += 0.1f)
            for (float z = -0.5f; z <= 0.5f; z += 0.1f) {
                const TwoBoneIkJob in = leg(vec3(0.09f + x, y, z));
                const float d = distance(in.root, in.target);
                if (d > in.soft_reach_start * 0.87f || d < 0.02f) continue;
                const TwoBoneIkResult r = solve(in);
                INFO("target " << in.target.x << " " << in.target.y << " " << in.target.z);
                REQUIRE(distance(r.end, in.target) <= 1e-4f);
                CHECK(r.reached);
                CHECK(distance(in.root, r.mid) == Approx(0.44f).margin(1e-5));
                CHECK(distance(r.mid, r.end) == Approx(0.43f).margin(1e-5));
                check_frames(in, r);
                ++solved;
            }
    CHECK(solved > 300);
}

TEST_CASE("two-bone IK bends toward the pole: knees forward, elbows back", "[ik]") {
    TwoBoneIkJob knee = leg(vec3(0.09f, 0.2f, 0.1f));
    const TwoBoneIkResult r = solve(knee);
    // The knee lies ahead (+Z) of the hip–ankle line.
    const vec3 line = (knee.target - knee.root) / distance(knee.target, knee.root);
    const vec3 offset = (r.mid - knee.root) - line * dot(r.mid - knee.root, line);
    CHECK(offset.z > 0.05f);
    CHECK(std::abs(offset.x) < 1e-5f);
    TwoBoneIkJob elbow = knee;
    elbow.pole = vec3(0, 0, -1);
    const TwoBoneIkResult e = solve(elbow);
    const vec3 elbow_offset = (e.mid - elbow.root) - line * dot(e.mid - elbow.root, line);
    CHECK(elbow_offset.z < -0.05f);
    CHECK(distance(e.end, elbow.target) < 1e-4f);
}

TEST_CASE("a straight limb gets the rest frame for either hinge sign", "[ik]") {
    TwoBoneIkJob in = leg(vec3(0.09f, 0.9f - 0.87f * 0.5f, 0.0f));
    in.soft_reach_start = 1.0f;
    in.target = vec3(0.09f, 0.9f - 0.87f, 0.0f);  // exactly full extension, straight down
    const TwoBoneIkResult r = solve(in);
    CHECK(std::abs(r.upper_rotation.w) == Approx(1.0f).margin(1e-4));
    CHECK(std::abs(r.lower_rotation.w) == Approx(1.0f).margin(1e-4));
    in.pole = vec3(0, 0, -1);
    in.hinge_sign = -1.0f;
    const TwoBoneIkResult arm = solve(in);
    CHECK(std::abs(arm.upper_rotation.w) == Approx(1.0f).margin(1e-4));
    CHECK(distance(arm.hinge_axis, vec3(1, 0, 0)) < 1e-5f);
}

TEST_CASE("out-of-reach targets are approached softly, never snapped", "[ik]") {
    const float full = 0.87f;
    float previous_reach = 0.0f;
    vec3 previous_mid(0.0f);
    for (float d = 0.80f; d <= 1.40f; d += 0.002f) {
        TwoBoneIkJob in = leg(vec3(0.09f, 0.9f - d * 0.8f, d * 0.6f));
        const TwoBoneIkResult r = solve(in);
        CHECK(r.reach < full);
        CHECK(r.reach >= previous_reach);
        CHECK(finite(r.mid));
        // The end moves no faster than the target (slope ≤ 1) and the knee has no jump.
        if (previous_reach > 0.0f) {
            CHECK(r.reach - previous_reach <= 0.002f + 1e-6f);
            CHECK(distance(r.mid, previous_mid) < 0.01f);
        }
        // The end stays on the root → target line.
        const vec3 dir = (in.target - in.root) / distance(in.target, in.root);
        CHECK(distance(r.end, in.root + dir * r.reach) < 1e-5f);
        if (d > 0.9f) CHECK_FALSE(r.reached);
        previous_reach = r.reach;
        previous_mid = r.mid;
    }
    CHECK(previous_reach > 0.99f * full);
}

TEST_CASE("degenerate IK inputs give finite poses with the bone lengths kept", "[ik]") {
    SECTION("target on the root") {
        TwoBoneIkJob in = leg(vec3(0.09f, 0.9f, 0.0f));
        const TwoBoneIkResult r = solve(in);
        CHECK(finite(r.mid));
        CHECK(finite(r.end));
        CHECK(distance(in.root, r.mid) == Approx(0.44f).margin(1e-5));
        CHECK(distance(r.mid, r.end) == Approx(0.43f).margin(1e-5));
        check_frames(in, r);
    }
    SECTION("pole parallel to the limb") {
        TwoBoneIkJob in = leg(vec3(0.09f, 0.4f, 0.0f));
        in.pole = vec3(0, -1, 0);
        const TwoBoneIkResult r = solve(in);
        CHECK(distance(r.end, in.target) < 1e-4f);
        check_frames(in, r);
    }
    SECTION("zero pole") {
        TwoBoneIkJob in = leg(vec3(0.09f, 0.4f, 0.1f));
        in.pole = vec3(0.0f);
        const TwoBoneIkResult r = solve(in);
        CHECK(distance(r.end, in.target) < 1e-4f);
    }
    SECTION("equal bones folded onto the root") {
        TwoBoneIkJob in = leg(vec3(0.09f, 0.9f, 0.0f));
        in.lower_length = in.upper_length;
        const TwoBoneIkResult r = solve(in);
        CHECK(finite(r.mid));
        CHECK(distance(in.root, r.mid) == Approx(0.44f).margin(1e-4));
    }
}

TEST_CASE("quaternions from axes and from vector pairs", "[ik]") {
    const quat q = quat_axis_angle(vec3(0.6f, 0.0f, 0.8f), 1.1);
    const quat r = quat_from_axes(quat_rotate(q, vec3(1, 0, 0)), quat_rotate(q, vec3(0, 1, 0)), quat_rotate(q, vec3(0, 0, 1)));
    CHECK(std::abs(quat_dot(q, r)) == Approx(1.0f).margin(1e-5));
    const vec3 from = vec3(0, 1, 0);
    const vec3 to = vec3(0.48f, 0.6f, 0.64f);
    CHECK(distance(quat_rotate(quat_from_to(from, to), from), to) < 1e-5f);
    CHECK(distance(quat_rotate(quat_from_to(from, -from), from), -from) < 1e-5f);
}

namespace {
bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same_bits(vec3 a, vec3 b) { return same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z); }
bool same_bits(quat a, quat b) { return same_bits(a.w, b.w) && same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z); }
bool same_result(const TwoBoneIkResult& a, const TwoBoneIkResult& b) {
    return same_bits(a.mid, b.mid) && same_bits(a.end, b.end) && same_bits(a.hinge_axis, b.hinge_axis) &&
           same_bits(a.upper_rotation, b.upper_rotation) && same_bits(a.lower_rotation, b.lower_rotation) &&
           same_bits(a.reach, b.reach) && a.reached == b.reached;
}
// A job drawn over the whole input envelope: limbs of any proportions, targets
// near, at and past full reach and onto the root, any pole (zero and parallel
// to the limb included), either hinge sign.
TwoBoneIkJob random_job(std::uint64_t& rng) {
    const auto uniform = [&](float lo, float hi) { return lo + (hi - lo) * static_cast<float>(splitmix64_unit(rng)); };
    const auto direction = [&] {
        vec3 v(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
        const float n = std::sqrt(dot(v, v));
        return n > 1e-3f ? v / n : vec3(0, -1, 0);
    };
    TwoBoneIkJob in;
    in.root = vec3(uniform(-3, 3), uniform(-1, 2), uniform(-3, 3));
    in.upper_length = uniform(0.05f, 0.6f);
    in.lower_length = uniform(0.05f, 0.6f);
    in.hinge_sign = uniform(0, 1) < 0.5f ? -1.0f : 1.0f;
    in.soft_reach_start = uniform(0, 1) < 0.8f ? 0.98f : uniform(0.5f, 1.0f);
    const float full = in.upper_length + in.lower_length;
    const float kind = uniform(0, 1);
    const vec3 dir = direction();
    if (kind < 0.05f) in.target = in.root;                                  // onto the root
    else if (kind < 0.15f) in.target = in.root + dir * (full * uniform(1.0f, 2.0f));  // past full reach
    else in.target = in.root + dir * (full * uniform(0.0f, 1.0f));
    const float pole_kind = uniform(0, 1);
    if (pole_kind < 0.05f) in.pole = vec3(0.0f);                            // zero pole
    else if (pole_kind < 0.1f) in.pole = dir * uniform(-2.0f, 2.0f);        // along the limb
    else in.pole = direction() * uniform(0.1f, 2.0f);
    return in;
}
}  // namespace

TEST_CASE("the lane solve gives the scalar solve's bits for 1 to 4 random jobs", "[ik][job]") {
    std::uint64_t rng = 0x1C0FFEEull;
    for (int round = 0; round < 20000; ++round) {
        const std::size_t count = 1 + static_cast<std::size_t>(round % 4);
        std::array<TwoBoneIkJob, 4> jobs;
        for (std::size_t k = 0; k < count; ++k) jobs[k] = random_job(rng);
        std::array<TwoBoneIkResult, 4> lanes;
        REQUIRE(TwoBoneIkLanesJob{std::span<const TwoBoneIkJob>(jobs.data(), count), std::span<TwoBoneIkResult>(lanes.data(), count)}.run());
        for (std::size_t k = 0; k < count; ++k) {
            const TwoBoneIkResult scalar = solve_two_bone_ik(jobs[k]);
            INFO("round " << round << " lane " << k);
            REQUIRE(same_result(lanes[k], scalar));
        }
    }
}

TEST_CASE("TwoBoneIkLanesJob refuses bad counts and bad jobs", "[ik][job]") {
    std::array<TwoBoneIkJob, 5> jobs;
    for (TwoBoneIkJob& j : jobs) j = leg(vec3(0.09f, 0.2f, 0.1f));
    std::array<TwoBoneIkResult, 5> results;
    CHECK(TwoBoneIkLanesJob{std::span<const TwoBoneIkJob>(jobs.data(), 4), std::span<TwoBoneIkResult>(results.data(), 4)}.validate());
    CHECK_FALSE(TwoBoneIkLanesJob{std::span<const TwoBoneIkJob>(jobs.data(), 5), std::span<TwoBoneIkResult>(results.data(), 5)}.validate());
    CHECK_FALSE(TwoBoneIkLanesJob{std::span<const TwoBoneIkJob>(jobs.data(), 0), std::span<TwoBoneIkResult>(results.data(), 0)}.validate());
    CHECK_FALSE(TwoBoneIkLanesJob{std::span<const TwoBoneIkJob>(jobs.data(), 2), std::span<TwoBoneIkResult>(results.data(), 3)}.validate());
    jobs[1].upper_length = -1.0f;
    CHECK_FALSE(TwoBoneIkLanesJob{std::span<const TwoBoneIkJob>(jobs.data(), 2), std::span<TwoBoneIkResult>(results.data(), 2)}.run());
    jobs[1].upper_length = 0.44f;
    jobs[0].target.x = NAN;
    CHECK_FALSE(TwoBoneIkLanesJob{std::span<const TwoBoneIkJob>(jobs.data(), 2), std::span<TwoBoneIkResult>(results.data(), 2)}.run());
}
