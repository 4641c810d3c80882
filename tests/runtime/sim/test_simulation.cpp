#include <catch2/catch.hpp>

#include "runtime/sim/fixed_step.hpp"
#include "runtime/gait/puppet.hpp"
#include "runtime/sim/simulation.hpp"

using namespace marionette;

namespace {
TickInput stick(double x, double y) {
    TickInput in;
    in.left_x = quantize_stick(x);
    in.left_y = quantize_stick(y);
    return in;
}
float speed_of(const PuppetState& s) { return std::sqrt(s.velocity.x * s.velocity.x + s.velocity.y * s.velocity.y); }
}  // namespace

TEST_CASE("same inputs give bit-identical states tick for tick", "[simulation]") {
    set_simulation_float_mode();
    const SimConfig config;
    Simulation a(config);
    Simulation b(config);
    CHECK(hash_state(a.state()) == hash_state(b.state()));
    for (int k = 0; k < 2000; ++k) {
        const double t = k / 240.0;
        const TickInput in = stick(0.8 * det::sin(t), 0.9 * det::cos(0.7 * t));
        a.step(in);
        b.step(in);
        REQUIRE(hash_state(a.state()) == hash_state(b.state()));
    }
    CHECK(a.state().tick == 2000);
}

TEST_CASE("the hash covers the state: any change changes it", "[simulation]") {
    Simulation sim{SimConfig{}};
    sim.step(stick(0, 1));
    const PuppetState base = sim.state();
    const std::uint64_t h = hash_state(base);
    PuppetState s = base;
    s.model_positions[21].y += 1e-6f;
    CHECK(hash_state(s) != h);
    s = base;
    s.input.buttons ^= 1;
    CHECK(hash_state(s) != h);
    s = base;
    s.breath_time += 1e-6f;
    CHECK(hash_state(s) != h);
    s = base;
    s.local_rotations[kPuppetJointCount + 3].x = 1.0f;  // past joint_count: not state
    CHECK(hash_state(s) == h);
}

TEST_CASE("the left stick drives the root: speed, direction and heading", "[simulation]") {
    const SimConfig config;
    Simulation sim(config);
    for (int k = 0; k < 240 * 3; ++k) sim.step(stick(0, 1));  // full up for 3 s
    const PuppetState& s = sim.state();
    CHECK(speed_of(s) == Approx(config.max_speed).epsilon(1e-4));
    CHECK(s.root_position.z < -6.0f);       // up moves away from the camera (−Z)
    // The reversal turns in place, then finishes its last degrees while speeding up.
    CHECK(std::abs(s.root_position.x) < 0.005f);
    CHECK(std::abs(std::abs(s.heading) - det::kPi) < 1e-3);  // facing −Z
    CHECK(s.locomotion_blend == 1.0f);
    for (int k = 0; k < 240 * 2; ++k) sim.step(stick(0, 0));  // release: decelerate and stand
    CHECK(speed_of(sim.state()) == 0.0f);
    CHECK(sim.state().locomotion_blend == 0.0f);
}

TEST_CASE("inputs inside the deadzone do not move the puppet", "[simulation]") {
    const SimConfig config;
    Simulation sim(config);
    for (int k = 0; k < 480; ++k) sim.step(stick(0.08, -0.05));
    CHECK(sim.state().root_position.x == 0.0f);
    CHECK(sim.state().root_position.z == 0.0f);
}

TEST_CASE("retune applies tunables and refuses structural changes", "[simulation]") {
    SimConfig config;
    Simulation sim(config);
    SimConfig faster = config;
    faster.max_speed = 1.0f;
    CHECK(sim.retune(faster).ok());
    for (int k = 0; k < 480; ++k) sim.step(stick(1, 0));
    CHECK(speed_of(sim.state()) == Approx(1.0f));
    SimConfig taller = config;
    taller.thigh_length = 0.5f;
    CHECK(sim.retune(taller).problem() == "puppet (skeleton proportions)");
    SimConfig rate = config;
    rate.tick_rate_hz = 120;
    CHECK(sim.retune(rate).problem() == "simulation.tick_rate_hz");
}

TEST_CASE("fixed-step driver runs whole ticks and caps catch-up", "[fixed_step]") {
    FixedStepDriver d = FixedStepDriver::at_rate(240, 8);
    CHECK(d.tick_ns == 4'166'666);
    CHECK(d.advance(4'000'000) == 0);
    CHECK(d.advance(1'000'000) == 1);
    CHECK(d.alpha() == Approx(833'334.0 / 4'166'666.0));
    CHECK(d.advance(1'000'000'000) == 8);  // a one-second stall runs 8 ticks, not 240
    CHECK(d.catch_up_cap_hits == 1);
    CHECK(d.dropped_ns > 900'000'000);
    CHECK(d.accumulated_ns < d.tick_ns);
}
