// The gait's behaviours, each checked on the simulated joints (not on the plan).
#include <catch2/catch.hpp>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>

#include "runtime/gait/gait.hpp"
#include "runtime/gait/puppet.hpp"
#include "runtime/sim/simulation.hpp"
#include "tests/alloc_counter.hpp"

using namespace marionette;

namespace {
TickInput stick(double x, double y) {
    TickInput in;
    in.left_x = quantize_stick(x);
    in.left_y = quantize_stick(y);
    return in;
}
float horizontal(vec3 a, vec3 b) { return std::sqrt((a.x - b.x) * (a.x - b.x) + (a.z - b.z) * (a.z - b.z)); }
// Stick deflection that commands `speed` with the default curve (bisection).
double deflection_for(double speed, const SimConfig& c) {
    double lo = c.stick_deadzone, hi = 1.0;
    for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (c.max_speed * stick_speed_fraction(static_cast<float>(mid), c) < speed ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}
void run_ticks(Simulation& sim, const TickInput& in, int n) {
    for (int k = 0; k < n; ++k) sim.step(in);
}
float lowest_sole_clearance(const PuppetState& s, const Terrain& t, const SimConfig& c) {
    float lowest = 1e9f;
    for (int foot : {kFootL, kFootR}) {
        const std::size_t f = static_cast<std::size_t>(foot);
        const vec3 points[3] = {s.model_positions[f] + quat_rotate(s.model_rotations[f], vec3(0.0f, -c.ankle_height, 0.0f)),
                                s.model_positions[f + 1],
                                s.model_positions[f + 1] + quat_rotate(s.model_rotations[f + 1], vec3(0.0f, 0.0f, c.toe_length))};
        for (const vec3& p : points) lowest = std::min(lowest, p.y - query_ground(t, p.x, p.z).height);
    }
    return lowest;
}
}  // namespace

TEST_CASE("on flat ground the mean speed tracks the stick within 2 percent from slow walk to full run", "[gait]") {
    const SimConfig c;
    for (double speed : {0.4, 0.8, 1.4, 1.9, 2.4, 3.0}) {
        INFO("commanded " << speed << " m/s");
        Simulation sim(c);
        const TickInput in = stick(0.0, deflection_for(speed, c));
        run_ticks(sim, in, 240 * 3);  // turn, speed up, settle
        // Four strides (eight steps) of the pelvis joint, sampled every quarter second.
        const float stride = 2.0f * std::fmax(c.min_step_duration, std::fmin(c.max_step_duration, c.step_length_multiplier / std::sqrt(static_cast<float>(speed))));
        const int ticks = static_cast<int>(4.0f * stride * 240.0f);
        double path = 0.0;
        vec3 last = sim.state().model_positions[kPelvis];
        for (int k = 1; k <= ticks; ++k) {
            sim.step(in);
            if (k % 60 == 0 || k == ticks) {
                path += horizontal(sim.state().model_positions[kPelvis], last);
                last = sim.state().model_positions[kPelvis];
            }
        }
        const double measured = path / (ticks / 240.0);
        CHECK(std::abs(measured - speed) / speed < 0.02);
    }
}

TEST_CASE("stance feet stay pinned and the first step from standstill is half length", "[gait]") {
    SimConfig c;
    Terrain rubble;
    for (int i = 0; i < 40; ++i)
        rubble.boxes.push_back({-1.0f + 0.05f * (i % 5), -0.6f * i, 1.0f, -0.6f * i + 0.3f, 0.01f * static_cast<float>(i % 7)});
    Simulation sim(c, rubble);
    const TickInput in = stick(0.0, 0.7);
    vec3 anchor[2] = {};
    bool stance[2] = {false, false};
    double worst = 0.0;
    float first_step = -1.0f;
    const vec3 start_left = sim.state().model_positions[kFootL];
    const vec3 start_right = sim.state().model_positions[kFootR];
    for (int k = 0; k < 240 * 6; ++k) {
        sim.step(in);
        const PuppetState& s = sim.state();
        for (int i = 0; i < 2; ++i) {
            const vec3 p = s.model_positions[static_cast<std::size_t>(i == 0 ? kFootL : kFootR)];
            const bool now = s.gait.feet[static_cast<std::size_t>(i)].swinging == 0;
            if (now && !stance[i]) anchor[i] = p;
            if (now) worst = std::max(worst, static_cast<double>(horizontal(p, anchor[i])));
            if (now && !stance[i] && first_step < 0.0f && k > 0)
                first_step = horizontal(p, i == 0 ? start_left : start_right);
            stance[i] = now;
        }
    }
    CHECK(worst < 0.5e-3);
    // The first step lands well short of a steady step (the steady stride is ~1.3 m per two steps).
    CHECK(first_step > 0.0f);
    CHECK(first_step < 0.6f);
}

TEST_CASE("running has flight phases and walking never does", "[gait]") {
    const SimConfig c;
    auto flight_ticks = [&](double speed) {
        Simulation sim(c);
        const TickInput in = stick(0.0, deflection_for(speed, c));
        run_ticks(sim, in, 240 * 3);
        int flying = 0;
        for (int k = 0; k < 240 * 3; ++k) {
            sim.step(in);
            // Off the ground: every sole point of both feet more than 5 mm up.
            if (lowest_sole_clearance(sim.state(), sim.terrain(), c) > 0.005f) ++flying;
        }
        return flying;
    };
    CHECK(flight_ticks(1.2) == 0);
    CHECK(flight_ticks(c.run_threshold - 0.1) == 0);
    CHECK(flight_ticks(2.6) > 60);
}

TEST_CASE("heading follows the stick at the turn rate and a reversal from a walk turns in place", "[gait]") {
    const SimConfig c;
    Simulation sim(c);
    run_ticks(sim, stick(0.0, 0.7), 240 * 3);  // walking toward −Z
    const float max_turn = static_cast<float>(c.turn_rate_deg_s * det::kDegToRad / c.tick_rate_hz) + 1e-5f;
    // A 90° turn: the heading moves at most the turn rate per tick and keeps walking.
    float before = sim.state().heading;
    for (int k = 0; k < 240; ++k) {
        sim.step(stick(0.7, 0.0));
        const float turned = static_cast<float>(std::abs(det::wrap_angle(sim.state().heading - before)));
        CHECK(turned <= max_turn);
        before = sim.state().heading;
    }
    CHECK(std::abs(det::wrap_angle(sim.state().heading - det::kHalfPi)) < 1e-3);
    CHECK(sim.state().gait.speed > 1.0f);
    // Reverse (180°): the puppet stops, turns in place stepping, then walks the other way.
    const vec3 at_reversal = sim.state().root_position;
    bool turned_in_place = false;
    float backwards = 0.0f;
    int steps_before = sim.state().gait.steps;
    for (int k = 0; k < 240 * 3; ++k) {
        sim.step(stick(-0.7, 0.0));
        const PuppetState& s = sim.state();
        if (s.gait.turning_in_place) {
            turned_in_place = true;
            CHECK(s.gait.speed == 0.0f);
        }
        // Never walks backwards along the old direction (+X) beyond where it reversed... nor forward.
        backwards = std::max(backwards, s.root_position.x - at_reversal.x);
    }
    CHECK(turned_in_place);
    CHECK(sim.state().gait.steps > steps_before + 2);
    CHECK(backwards < 0.05f);
    CHECK(std::abs(det::wrap_angle(sim.state().heading + det::kHalfPi)) < 1e-3);
    CHECK(sim.state().root_position.x < at_reversal.x - 1.0f);
}

TEST_CASE("released on uneven ground the puppet rests within one step, pelvis down to the lower foot, breathing", "[gait]") {
    SimConfig c;
    Terrain ground;
    ground.boxes.push_back({0.0f, -20.0f, 5.0f, 20.0f, 0.08f});  // facing −Z, the right (+X) foot stands 8 cm higher
    Simulation sim(c, ground);
    run_ticks(sim, stick(0.0, 0.5), 240 * 2);
    const int steps_at_release = sim.state().gait.steps;
    run_ticks(sim, stick(0.0, 0.0), 1);
    CHECK(sim.state().gait.speed == 0.0f);  // stopping is immediate in movement
    run_ticks(sim, stick(0.0, 0.0), 240);
    const PuppetState& s = sim.state();
    CHECK(s.gait.mode == GaitMode::idle);
    CHECK(s.gait.steps - steps_at_release <= 2);  // the swing foot plants, at most one more step
    CHECK(s.gait.feet[0].swinging == 0);
    CHECK(s.gait.feet[1].swinging == 0);
    CHECK(s.gait.feet[0].ground == Approx(0.0f).margin(1e-4));   // left, on the ground
    CHECK(s.gait.feet[1].ground == Approx(0.08f).margin(1e-4));  // right, on the box
    // Both feet on the ground, and the lower leg reaches: the pelvis went down for it.
    CHECK(lowest_sole_clearance(s, ground, c) > -1e-3f);
    CHECK(lowest_sole_clearance(s, ground, c) < 1e-3f);
    const vec3 hip = s.model_positions[kThighL];
    const vec3 ankle = s.model_positions[kFootL];
    const float leg = std::sqrt((hip.x - ankle.x) * (hip.x - ankle.x) + (hip.y - ankle.y) * (hip.y - ankle.y) + (hip.z - ankle.z) * (hip.z - ankle.z));
    CHECK(leg < c.thigh_length + c.shin_length);
    CHECK(std::abs(ankle.y - c.ankle_height) < 1e-3f);
    // Breathing: over one breath the pelvis rises and falls by about twice the amplitude.
    float lo = 1e9f, hi = -1e9f;
    for (int k = 0; k < static_cast<int>(240 * c.breath_period_s); ++k) {
        sim.step(stick(0.0, 0.0));
        lo = std::min(lo, sim.state().model_positions[kPelvis].y);
        hi = std::max(hi, sim.state().model_positions[kPelvis].y);
    }
    CHECK(hi - lo > 1.5f * c.breath_amplitude);
    CHECK(hi - lo < 2.5f * c.breath_amplitude);
}

TEST_CASE("stopping mid-step plants the swing foot quickly and nothing teleports", "[gait]") {
    const SimConfig c;
    for (int release_tick : {240 * 2 + 17, 240 * 2 + 61, 240 * 2 + 103}) {
        INFO("released at tick " << release_tick);
        Simulation sim(c);
        run_ticks(sim, stick(0.0, 1.0), release_tick);
        PuppetState previous = sim.state();
        float fastest_foot = 0.0f;
        int planted_after = -1;
        for (int k = 0; k < 240; ++k) {
            sim.step(stick(0.0, 0.0));
            const PuppetState& s = sim.state();
            for (int foot : {kFootL, kFootR})
                fastest_foot = std::max(fastest_foot, horizontal(s.model_positions[static_cast<std::size_t>(foot)],
                                                                 previous.model_positions[static_cast<std::size_t>(foot)]));
            if (planted_after < 0 && !s.gait.feet[0].swinging && !s.gait.feet[1].swinging) planted_after = k;
            previous = s;
        }
        CHECK(fastest_foot < 0.03f);  // under 7.2 m/s per tick: no jump
        CHECK(planted_after >= 0);
        CHECK(planted_after <= static_cast<int>(c.stop_transition_s * 240) + 2);
        CHECK(sim.state().gait.mode == GaitMode::idle);
    }
}

TEST_CASE("slopes reduce the speed by the configured factor per degree, and climbing is capped at 0.6 m/s", "[gait]") {
    const float grade = static_cast<float>(std::tan(15.0 * det::kDegToRad));
    Terrain hill;
    hill.slopes.push_back({-5.0f, -40.0f, 5.0f, -1.0f, 39.0f * grade, 0.0f, -grade});  // rises toward −Z
    {
        // 15° at a walk: the slope factor alone (0.85 × 1.5 m/s climbs 0.33 m/s).
        SimConfig c;
        c.max_speed = 1.5f;
        Simulation sim(c, hill);
        run_ticks(sim, stick(0.0, 1.0), 240 * 4);
        CHECK(sim.state().root_position.z < -3.0f);
        CHECK(sim.state().gait.speed == Approx(c.max_speed * (1.0f - c.slope_speed_factor * 15.0f)).epsilon(1e-3));
    }
    {
        // At a full run 0.85 × 3 m/s would climb 0.68 m/s: capped at 0.6 m/s of climb.
        SimConfig c;
        Simulation sim(c, hill);
        run_ticks(sim, stick(0.0, 1.0), 240 * 4);
        CHECK(sim.state().root_position.z < -3.0f);
        CHECK(sim.state().gait.speed == Approx(0.6f / grade).epsilon(1e-3));
    }
}

TEST_CASE("the swing foot clears a 20 cm step up and down", "[gait]") {
    SimConfig c;
    Terrain step;
    step.boxes.push_back({-3.0f, -3.0f, 3.0f, -1.5f, 0.2f});
    Simulation sim(c, step);
    float lowest = 1e9f;
    for (int k = 0; k < 240 * 5; ++k) {
        sim.step(stick(0.0, 0.6));
        lowest = std::min(lowest, lowest_sole_clearance(sim.state(), step, c));
    }
    CHECK(sim.state().root_position.z < -3.5f);  // crossed the whole box
    CHECK(lowest > -1e-3f);
}

TEST_CASE("stepping down a 20 cm riser at a fast walk keeps the knees under 1500 deg/s and the soles above ground", "[gait]") {
    SimConfig c;
    Terrain step;
    step.boxes.push_back({-3.0f, -3.0f, 3.0f, 1.0f, 0.2f});  // the puppet starts on top and walks off at z = −3
    Simulation sim(c, step);
    double fastest_knee = 0.0;
    float lowest = 1e9f;
    PuppetState previous = sim.state();
    for (int k = 0; k < 240 * 4; ++k) {
        sim.step(stick(0.0, 0.8));
        const PuppetState& s = sim.state();
        for (int shin : {kShinL, kShinR}) {
            const std::size_t j = static_cast<std::size_t>(shin);
            fastest_knee = std::max(fastest_knee, quat_angle_between(previous.local_rotations[j], s.local_rotations[j]) * 240.0 * det::kRadToDeg);
        }
        lowest = std::min(lowest, lowest_sole_clearance(s, step, c));
        previous = s;
    }
    CHECK(sim.state().root_position.z < -4.0f);  // walked off the box
    CHECK(sim.state().gait.feet[0].ground < 0.01f);
    CHECK(fastest_knee < 1500.0);
    CHECK(lowest > -1e-3f);
}

TEST_CASE("the hands trail their swing: wrist tilts against the hand path's motion, straight at rest", "[gait]") {
    SimConfig c;
    Simulation sim(c, Terrain{});
    run_ticks(sim, stick(0.0, 0.0), 240);
    for (int hand : {kHandL, kHandR})
        CHECK(quat_angle_between(sim.state().local_rotations[static_cast<std::size_t>(hand)], quat_identity()) < 1e-4);
    // Walking toward −Z: between ticks the hand's bone direction (−Y of its
    // frame) turns away from the direction the wrist is moving in.
    run_ticks(sim, stick(0.0, 0.7), 240 * 2);
    double largest_tilt = 0.0;
    int trailing = 0, samples = 0;
    for (int k = 0; k < 240; ++k) {
        const PuppetState before = sim.state();
        sim.step(stick(0.0, 0.7));
        const PuppetState& s = sim.state();
        for (int hand : {kHandL, kHandR}) {
            const std::size_t j = static_cast<std::size_t>(hand);
            largest_tilt = std::max(largest_tilt, quat_angle_between(s.local_rotations[j], quat_identity()));
            // Wrist velocity relative to the pelvis, along the heading (−Z).
            const float moving = -((s.model_positions[j].z - s.model_positions[kPelvis].z) -
                                   (before.model_positions[j].z - before.model_positions[kPelvis].z));
            const vec3 forearm = quat_rotate(s.model_rotations[j - 1], vec3(0.0f, -1.0f, 0.0f));
            const vec3 bone = quat_rotate(s.model_rotations[j], vec3(0.0f, -1.0f, 0.0f));
            const float tilt_forward = -(bone.z - forearm.z);  // hand points further along −Z than the forearm
            if (std::fabs(moving) > 1e-4f) {
                ++samples;
                if (moving * tilt_forward < 0.0f) ++trailing;
            }
        }
    }
    CHECK(largest_tilt > 5.0 * det::kDegToRad);
    CHECK(samples > 100);
    CHECK(trailing > samples * 8 / 10);
}

TEST_CASE("step never allocates", "[gait]") {
    Terrain rubble;
    for (int i = 0; i < 50; ++i) rubble.boxes.push_back({-2.0f, -0.5f * i, 2.0f, -0.5f * i + 0.2f, 0.01f * (i % 8)});
    Simulation sim(SimConfig{}, rubble);
    const std::uint64_t before = test::allocation_count();
    for (int k = 0; k < 240 * 4; ++k) sim.step(stick(0.3 * std::sin(k / 200.0), k < 700 ? 1.0 : 0.0));
    CHECK(test::allocation_count() - before == 0);
}
