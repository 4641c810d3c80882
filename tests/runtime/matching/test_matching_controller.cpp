// The motion-matching controller on a synthetic database: it follows the
// desired velocity and facing, searches and jumps with inertialization (the pose
// never jumps), stays deterministic, and never allocates in step().
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "runtime/matching/matching_controller.hpp"
#include "runtime/math/det_math.hpp"
#include "tests/alloc_counter.hpp"
#include "tests/runtime/matching/matching_fixture.hpp"

using namespace marionette;

namespace {
struct Rig {
    test::MatchingFixture fixture = test::make_matching_fixture(24, 120, 3);
    MatchingDatabase db;
    Rig() { REQUIRE(build_matching_database(fixture.source(), {}, db).ok()); }
};
TrajectoryGoal goal_of(double speed, double heading) {
    double s = 0.0, c = 0.0;
    det::sin_cos(heading, s, c);
    return {static_cast<float>(speed * s), static_cast<float>(speed * c), static_cast<float>(heading)};
}
// Joint speeds of the fixture's seven-joint pose, tick to tick: each joint's
// (not the root's) angular speed, and the largest change of any joint's speed
// since the last tick (rad/s per tick), from the third pose on (0 before: the
// first speed needs two poses, the first change three).
struct SpeedSteps {
    std::array<quat, 7> previous{};
    std::array<double, 7> previous_speed{};
    int poses = 0;
    double fastest = 0.0;  // this tick's fastest joint, rad/s
    double step(const std::array<quat, 7>& r, float dt) {
        double largest = 0.0;
        fastest = 0.0;
        for (size_t j = 1; j < 7 && poses >= 1; ++j) {
            const double speed = quat_angle_between(previous[j], r[j]) / dt;
            fastest = std::max(fastest, speed);
            if (poses >= 2) largest = std::max(largest, std::fabs(speed - previous_speed[j]));
            previous_speed[j] = speed;
        }
        previous = r;
        ++poses;
        return largest;
    }
};
}  // namespace

TEST_CASE("matching controller: step refuses bad spans and states, touching nothing", "[matching]") {
    Rig rig;
    MatchingController mc(rig.fixture.source(), rig.db, {});
    MatchingState s = mc.initial_state(vec3(0.0f), 0.0f);
    std::array<quat, 7> r{};
    std::array<vec3, 7> t{};
    MatchingInput in;
    in.dt = 1.0f / 240.0f;
    CHECK_FALSE(mc.step(s, in, {std::span<quat>(r.data(), 6), std::span<vec3>(t.data(), 6)}));
    MatchingState off = s;
    off.frame = rig.db.frame_count;
    CHECK_FALSE(mc.step(off, in, {r, t}));
    CHECK(off.frame == rig.db.frame_count);
    CHECK(mc.step(s, in, {r, t}));
}

TEST_CASE("matching controller: follows speed and heading, jumps without pops, allocation-free", "[matching]") {
    Rig rig;
    MatchingController mc(rig.fixture.source(), rig.db, {});
    std::uint64_t rng = 99;
    for (int trial = 0; trial < 6; ++trial) {
        const double speed = 0.3 + 2.4 * test::fixture_unit(rng);
        const double heading = (test::fixture_unit(rng) * 2.0 - 1.0) * 3.0;
        MatchingState s = mc.initial_state(vec3(1.0f, 0.0f, -2.0f), 0.5f);
        std::array<quat, 7> r{};
        std::array<vec3, 7> t{}, previous{};
        MatchingInput in;
        in.dt = 1.0f / 240.0f;
        in.goal = goal_of(speed, heading);
        const std::uint64_t allocations = test::allocation_count();
        vec3 start{}, last_step{};
        double worst_root_jerk = 0.0;
        for (int tick = 0; tick < 240 * 4; ++tick) {
            REQUIRE(mc.step(s, in, {r, t}));
            if (tick == 240) start = mc.root_position(s);
            const vec3 step = t[0] - previous[0];
            if (tick > 1) worst_root_jerk = std::max(worst_root_jerk, static_cast<double>(glm::length(step - last_step)));
            last_step = step;
            previous = t;
        }
        CHECK(test::allocation_count() == allocations);
        INFO("trial " << trial << " speed " << speed << " heading " << heading);
        const vec3 end = mc.root_position(s);
        const double covered = std::sqrt((end.x - start.x) * (end.x - start.x) + (end.z - start.z) * (end.z - start.z));
        CHECK(covered == Approx(speed * 3.0).epsilon(0.1));
        CHECK(std::fabs(det::wrap_angle(mc.root_heading(s) - heading)) < 0.2);
        CHECK(s.searches > 30);
        // The root's motion per tick changes by under 6 mm from one tick to the next:
        // jumps are inertialized, so the root never jumps by a position offset (nor,
        // since the offsets carry the velocity difference, by a velocity).
        CHECK(worst_root_jerk < 0.006);
    }
}

TEST_CASE("matching controller: identical inputs give identical states", "[matching]") {
    Rig rig;
    MatchingController a(rig.fixture.source(), rig.db, {});
    MatchingState s1 = a.initial_state(vec3(0.0f), 0.0f), s2 = s1;
    std::array<quat, 7> r{};
    std::array<vec3, 7> t{};
    for (int tick = 0; tick < 600; ++tick) {
        MatchingInput in;
        in.dt = 1.0f / 240.0f;
        in.goal = goal_of(tick < 300 ? 1.4 : 2.5, tick * 0.004);
        REQUIRE(a.step(s1, in, {r, t}));
        REQUIRE(a.step(s2, in, {r, t}));
    }
    CHECK(s1.frame == s2.frame);
    CHECK(s1.world_dx == s2.world_dx);
    CHECK(s1.jumps == s2.jumps);
    CHECK(s1.jumps > 0);
}

// Velocity inertialization (docs/motion-matching.md): on a jump the offset to the
// new frame and the offset's velocity (shown pose's − new frame's) decay as
// critically damped springs, so a jump adds no joint-speed spike beyond what
// the clips themselves move, and the joints' velocity does not step at a jump.
// Generated stick changes (fixed seed) over the fixture's speeds and turns.
TEST_CASE("matching controller: a jump adds no joint-speed spike beyond the clips' own", "[matching]") {
    Rig rig;
    const MatchingSource source = rig.fixture.source();
    const size_t n = 7;
    // The clips' own fastest joint (local rotation, not the root), frame to frame.
    double clip_speed = 0.0;
    for (const MatchingClipRange& c : rig.fixture.clips)
        for (int f = c.first_frame; f + 1 < c.first_frame + c.frame_count; ++f)
            for (size_t j = 1; j < n; ++j)
                clip_speed = std::max(clip_speed, quat_angle_between(source.rotations[static_cast<size_t>(f) * n + j],
                                                                     source.rotations[static_cast<size_t>(f + 1) * n + j]) * source.frame_rate);
    REQUIRE(clip_speed > 1.0);
    MatchingController mc(source, rig.db, {});
    std::uint64_t rng = 7;
    const float dt = 1.0f / 240.0f;
    double worst_speed = 0.0, worst_jump_step = 0.0, worst_steady_step = 0.0;
    std::int64_t jumps = 0;
    for (int trial = 0; trial < 8; ++trial) {
        MatchingState s = mc.initial_state(vec3(0.0f), 0.0f);
        std::array<quat, 7> r{};
        std::array<vec3, 7> t{};
        SpeedSteps speeds;
        MatchingInput in;
        in.dt = dt;
        for (int tick = 0; tick < 240 * 6; ++tick) {
            if (tick % 120 == 0) in.goal = goal_of(0.2 + 2.6 * test::fixture_unit(rng), (test::fixture_unit(rng) * 2.0 - 1.0) * 3.0);
            const std::int64_t before = s.jumps;
            REQUIRE(mc.step(s, in, {r, t}));
            const double step = speeds.step(r, dt);
            worst_speed = std::max(worst_speed, speeds.fastest);
            double& worst = s.jumps != before ? worst_jump_step : worst_steady_step;
            worst = std::max(worst, step);
        }
        jumps += s.jumps;
    }
    INFO("clips' fastest joint " << clip_speed << " rad/s, shown " << worst_speed << " rad/s; speed step at a jump "
                                 << worst_jump_step << ", elsewhere " << worst_steady_step << " rad/s per tick; " << jumps << " jumps");
    CHECK(jumps > 100);
    CHECK(worst_speed <= 1.05 * clip_speed);
    CHECK(worst_jump_step <= 1.5 * worst_steady_step);
}

// Actions (a button's labelled clip, issue #14): a squat clip, in place, is
// added to the synthetic database as an action. It is in the database but
// never a search answer, and it leaves the locomotion's features bit for bit
// as they were. Requested while walking, it plays from its first frame to its
// end with its own root motion (the root stays put), a second request while it
// plays and an index out of range do nothing, then a search takes the puppet
// back into the locomotion, which follows the stick again. Entry and exit are
// inertialized: no joint's speed steps at them by more than 1.5× the largest
// step elsewhere; nothing allocates.
TEST_CASE("matching controller: an action clip plays on request, entered and left without pops, then matching resumes",
          "[matching][action]") {
    test::MatchingFixture fixture = test::make_matching_fixture(24, 120, 3);
    const std::int32_t action_first = static_cast<std::int32_t>(fixture.contacts.size());
    const int action_frames = 60;  // 2 s at 30 Hz
    for (int f = 0; f < action_frames; ++f) {
        const double a = 0.6 * det::sin(3.141592653589793 * f / (action_frames - 1));
        fixture.rotations.push_back(quat_identity());
        fixture.translations.push_back(vec3(0.0f, static_cast<float>(0.9 - 0.2 * a), 0.0f));
        for (int leg = 0; leg < 2; ++leg) {
            fixture.rotations.push_back(quat_axis_angle(vec3(1.0f, 0.0f, 0.0f), -a));
            fixture.translations.push_back(vec3(leg == 0 ? 0.1f : -0.1f, 0.0f, 0.0f));
            fixture.rotations.push_back(quat_axis_angle(vec3(1.0f, 0.0f, 0.0f), 2.0 * a));
            fixture.translations.push_back(vec3(0.0f, -0.45f, 0.0f));
            fixture.rotations.push_back(quat_identity());
            fixture.translations.push_back(vec3(0.0f, -0.42f, 0.0f));
        }
        fixture.contacts.push_back(3);
    }
    const std::vector<MatchingClipRange> actions{{action_first, action_frames}};
    MatchingSource source = fixture.source();
    MatchingDatabase plain;
    REQUIRE(build_matching_database(source, {}, plain).ok());
    source.actions = actions;
    MatchingDatabase db;
    REQUIRE(build_matching_database(source, {}, db).ok());
    REQUIRE(db.action_begin.size() == 1);
    CHECK(db.matched_frames == plain.frame_count);
    CHECK(db.action_begin[0] == plain.frame_count);
    CHECK(db.frame_count == plain.frame_count + action_frames);
    for (int f = db.action_begin[0]; f < db.frame_count; ++f) CHECK(db.searchable[static_cast<size_t>(f)] == 0);
    CHECK(std::equal(plain.features.begin(), plain.features.end(), db.features.begin()));
    CHECK(plain.mean == db.mean);
    CHECK(plain.inv_scale == db.inv_scale);

    MatchingController mc(source, db, {});
    const float dt = 1.0f / 240.0f;
    MatchingState s = mc.initial_state(vec3(0.0f), 0.0f);
    std::array<quat, 7> r{};
    std::array<vec3, 7> t{};
    SpeedSteps speeds;
    MatchingInput in;
    in.dt = dt;
    in.goal = goal_of(1.2, 0.4);
    double worst_edge_step = 0.0, worst_steady_step = 0.0;
    int entered = -1, left = -1, first_bad_tick = -1, acting_ticks = 0;
    vec3 root_at_entry{}, after_start{};
    const std::uint64_t allocations = test::allocation_count();
    for (int tick = 0; tick < 240 * 7; ++tick) {
        in.action = tick == 240 ? 0 : (tick == 300 ? 0 : (tick == 310 ? 5 : -1));
        const bool was_acting = s.action >= 0;
        REQUIRE(mc.step(s, in, {r, t}));
        const bool acting = s.action >= 0;
        if (acting && !was_acting) entered = tick, root_at_entry = mc.root_position(s);
        if (!acting && was_acting) left = tick;
        if (acting) {
            // Checked after the loop (Catch's messages allocate).
            const vec3 p = mc.root_position(s);
            const bool in_clip = s.frame >= db.action_begin[0] && s.frame < db.frame_count;
            const bool put = std::fabs(p.x - root_at_entry.x) < 1e-4f && std::fabs(p.z - root_at_entry.z) < 1e-4f;  // the squat's root stays put
            if ((!in_clip || !put) && first_bad_tick < 0) first_bad_tick = tick;
            ++acting_ticks;
        }
        if (left >= 0 && tick == left + 240) after_start = mc.root_position(s);
        double& worst = acting != was_acting ? worst_edge_step : worst_steady_step;
        worst = std::max(worst, speeds.step(r, dt));
    }
    CHECK(test::allocation_count() == allocations);
    CHECK(first_bad_tick == -1);
    CHECK(acting_ticks == left - entered);
    CHECK(entered == 240);
    // The clip's 59 frame intervals at 30 Hz: 472 ticks, give or take the frame the end lands on.
    CHECK(left - entered >= 468);
    CHECK(left - entered <= 480);
    CHECK(s.action == -1);
    CHECK(s.frame < db.matched_frames);
    INFO("speed step at entry/exit " << worst_edge_step << ", elsewhere " << worst_steady_step << " rad/s per tick");
    CHECK(worst_edge_step <= 1.5 * worst_steady_step);
    // Back in the locomotion it follows the stick: 1.2 m/s over the last 2 s, facing 0.4 rad.
    const vec3 end = mc.root_position(s);
    const double covered = std::sqrt((end.x - after_start.x) * (end.x - after_start.x) + (end.z - after_start.z) * (end.z - after_start.z));
    const double seconds = (240.0 * 7 - 1 - (left + 240)) / 240.0;
    CHECK(covered == Approx(1.2 * seconds).epsilon(0.1));
    CHECK(std::fabs(det::wrap_angle(mc.root_heading(s) - 0.4)) < 0.2);
}
