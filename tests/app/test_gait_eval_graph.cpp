// gait-eval's metrics with a motion graph (app/eval/gait_eval.cpp): stance comes from the
// graph controller's foot contacts, the feet are the graph's own foot joints, and
// a walk on the embedded default graph gives finite metrics with steps and a
// measured speed hold.
#include <catch2/catch.hpp>

#include <cmath>

#include "app/config/config.hpp"
#include "app/graph/default_graph.hpp"
#include "app/eval/gait_eval.hpp"
#include "app/config/program_source.hpp"
#include "app/config/terrain_file.hpp"
#include "app/graph/graph_files.hpp"
#include "runtime/sim/tick_input.hpp"
#include "tests/test_support.hpp"
#include "runtime/sim/simulation.hpp"

using namespace marionette;

TEST_CASE("gait-eval: stance is the gait's plan, or the graph's foot contacts with a graph", "[gait_eval]") {
    PuppetState s;
    s.motion_source = kSourceGait;
    s.gait.feet[0].swinging = 0;
    s.gait.feet[1].swinging = 1;
    s.graph.contacts = kContactRight;  // ignored while the gait drives
    CHECK(foot_in_stance(s, 0));
    CHECK_FALSE(foot_in_stance(s, 1));
    s.motion_source = kSourceGraph;  // now the contacts decide, whatever the gait state says
    CHECK_FALSE(foot_in_stance(s, 0));
    CHECK(foot_in_stance(s, 1));
    s.graph.contacts = kContactLeft | kContactRight;
    CHECK(foot_in_stance(s, 0));
    CHECK(foot_in_stance(s, 1));
    // graph_feet: the pins decide (a foot in contact but let go for slipping is not planted).
    s.motion_source = kSourceGraphFeet;
    s.graph.contacts = kContactLeft | kContactRight;
    s.feet.feet[0].contact = 1;
    s.feet.feet[1].contact = 2;
    CHECK(foot_in_stance(s, 0));
    CHECK_FALSE(foot_in_stance(s, 1));
}

TEST_CASE("gait-eval: a walk on the default motion graph gives finite metrics from the graph's feet", "[gait_eval]") {
    const AppConfig shipped = default_config();
    const SimConfig& config = shipped.sim;
    const auto graph = std::make_shared<const MotionGraph>(build_default_motion_graph(config, shipped.graph_build));
    const StickProgram program = load_program("builtin:fast_walk");
    const GaitMetrics m = evaluate_gait(config, program, {}, graph);
    CHECK(m.motion_source == "graph");
    CHECK(check_gait_metrics_finite(m).ok());
    CHECK(m.ticks > 0);
    // The graph walks: feet leave and touch the ground, the 6 s hold is measured.
    CHECK(m.steps >= 4);
    CHECK(m.speed_windows == 1);
    CHECK(m.speed_error_pct >= 0.0);
    CHECK(m.speed_error_pct < 100.0);
    // The deepest point is named from the graph skeleton's points, not the puppet's sole.
    if (!m.deepest_point.empty()) CHECK(m.deepest_point.find("sole under the ankle") == std::string::npos);
    // Skate is measured while a contact flag holds: finite and under a leg length.
    CHECK(m.foot_skate_mm >= 0.0);
    CHECK(m.foot_skate_mm < 900.0);
    // The gait run of the same program is a different motion source.
    const GaitMetrics gait = evaluate_gait(config, program);
    CHECK(gait.motion_source == "gait");
    CHECK(gait.final_hash != m.final_hash);
}

TEST_CASE("gait-eval: heading error of one tick, in the gait's stick convention and wrapped", "[gait_eval]") {
    // atan2(x, −y): stick up (y = −1) is heading 0, stick right (x = 1) is +90°.
    CHECK(stick_heading_error_deg(0.0, -1.0, 0.0) == Approx(0.0).margin(1e-9));
    CHECK(stick_heading_error_deg(1.0, 0.0, 0.0) == Approx(90.0).margin(1e-6));
    CHECK(stick_heading_error_deg(1.0, 0.0, 1.5707963267948966) == Approx(0.0).margin(1e-6));
    CHECK(stick_heading_error_deg(0.0, 1.0, 0.0) == Approx(180.0).margin(1e-6));
    // Across ±180°: stick at 179°, heading at −179° is 2° off, not 358°.
    const double deg = 3.14159265358979 / 180.0;
    CHECK(stick_heading_error_deg(std::sin(179.0 * deg), -std::cos(179.0 * deg), -179.0 * deg) == Approx(2.0).margin(1e-6));
    // Generated (fixed seed): every direction and offset in (−180, 180) reads back as |offset|.
    std::uint32_t seed = 12345u;
    auto next = [&] { seed = seed * 1664525u + 1013904223u; return static_cast<double>(seed >> 8) / 16777216.0; };
    for (int i = 0; i < 500; ++i) {
        const double direction = (next() * 2.0 - 1.0) * 180.0 * deg;
        const double offset = (next() * 2.0 - 1.0) * 179.0;
        const double heading = direction - offset * deg;
        CHECK(stick_heading_error_deg(std::sin(direction), -std::cos(direction), heading) == Approx(std::fabs(offset)).margin(1e-6));
    }
}

TEST_CASE("gait-eval: heading error is the mean over the second half of each moving hold", "[gait_eval]") {
    // Hold 1: ticks 0..99, stick right (+90°); hold 2: ticks 200..239, stick up (0°).
    HeadingErrorMeter meter({{0, 100, 1.0, 0.0}, {200, 240, 0.0, -1.0}});
    const double deg = 3.14159265358979 / 180.0;
    for (std::uint64_t k = 0; k < 300; ++k) {
        double heading = 0.0;                          // first half of hold 1 and between holds: not counted
        if (k >= 50 && k < 100) heading = 60.0 * deg;  // 30° short of the stick
        if (k >= 200 && k < 220) heading = 90.0 * deg; // first half of hold 2: not counted
        if (k >= 220 && k < 240) heading = -10.0 * deg; // 10° off
        meter.add(k, heading);
    }
    CHECK(meter.samples() == 70);
    CHECK(meter.mean_deg() == Approx((50 * 30.0 + 20 * 10.0) / 70.0).epsilon(1e-9));
    // No moving hold: no samples, and the mean says so (−1), not a perfect 0.
    HeadingErrorMeter none({});
    none.add(0, 1.0);
    CHECK(none.samples() == 0);
    CHECK(none.mean_deg() == -1.0);
}

TEST_CASE("gait-eval: the heading error is measured on a real run, and is not 0 when the puppet faces away", "[gait_eval]") {
    const AppConfig shipped = default_config();
    const StickProgram program = load_program("builtin:fast_walk");
    const GaitMetrics gait = evaluate_gait(shipped.sim, program);
    CHECK(gait.heading_samples > 0);
    CHECK(gait.heading_error_deg >= 0.0);
    CHECK(gait.heading_error_deg < 10.0);
    // A known non-zero error: the heading may turn at only 10°/s. 3 s up
    // (heading 0: no turn), then 3 s right (+90°): the measured half of the second
    // hold runs from 2.25 s to 3 s into it, when the heading has turned about
    // 22.5°…30° (the turn starts as the stick moves), so it reads about 90 − 26 = 64°
    // there and the mean over both holds' measured halves about 32°.
    SimConfig slow = shipped.sim;
    slow.turn_rate_deg_s = 10.0f;
    const StickProgram turn = parse_stick_program("ramp 100ms ly=-1\nhold 3s\nramp 100ms lx=1 ly=0\nhold 3s\n", "turn.prog");
    const GaitMetrics turned = evaluate_gait(slow, turn);
    CHECK(turned.heading_samples > 0);
    CHECK(turned.heading_error_deg > 25.0);
    CHECK(turned.heading_error_deg < 40.0);
    const GaitMetrics free_turn = evaluate_gait(shipped.sim, turn);  // 360°/s: faces the stick long before
    CHECK(free_turn.heading_error_deg < 2.0);
}

// Issue 14: matching's knees snapped when a foot pin let go (1557 °/s on circle,
// 1592 on run, flat ground) and when keep_above_ground lifted a foot in one tick
// (4855 °/s, stairs run). The pins now let go through an inertialized offset and
// the lift is a spring toward the depth predicted 0.1 s ahead (FootPlacementJob::smooth_feet).
TEST_CASE("gait-eval: matching's joint speed stays under the limit where pin releases snapped", "[gait_eval][matching]") {
    const AppConfig shipped = default_config();
    SimConfig config = shipped.sim;
    config.motion_source = MotionSourceSetting::matching;
    config.terrain_name = "flat";  // the shipped configuration's terrain is not flat
    config.terrain = load_terrain("flat");
    const auto graph = std::make_shared<const MotionGraph>(build_default_motion_graph(config, shipped.graph_build));
    for (const char* name : {"builtin:circle", "builtin:run"}) {
        INFO(name);
        const GaitMetrics m = evaluate_gait(config, load_program(name), {}, graph);
        CHECK(m.motion_source == "matching");
        CHECK(m.max_joint_speed_deg_s < 1500.0);
        CHECK(m.penetration_mm <= 1.0);
        CHECK(m.foot_skate_mm <= 2.0);
    }
    // Stairs: the one-tick lift's 4,855 °/s went first (1,650 left), then the
    // snaps of the lift's floor on a riser and of the foot's ground rate limit
    // (1,463 → 1,392 °/s on this run; 1,527 and 1,467 on fast_walk and circle).
    config.terrain_name = "stairs";
    config.terrain = load_terrain("stairs");
    const GaitMetrics stairs = evaluate_gait(config, load_program("builtin:run"), {}, graph);
    CHECK(stairs.max_joint_speed_deg_s < 1500.0);
    CHECK(stairs.penetration_mm <= 1.0);
    CHECK(stairs.foot_skate_mm <= 2.0);
}

// Matching's actions (issue #14): the graph stays the sequencer of actions. On
// the default graph, each of the four mapped buttons ([motion_graph.buttons]:
// south jump, east wave, west bow, north look_around), pressed while walking or
// standing, plays that label's clip from its first frame to its end (the
// state's action index set for the clip's length at 240 Hz, ±1 frame), a press
// while it plays starts nothing new, and matching then resumes (no action, a
// locomotion frame). Then the shipped actions.prog (all four buttons, walking
// and standing) on flat and stairs keeps the limits: joint speed
// < 1500 °/s, penetration ≤ 1 mm, skate ≤ 2 mm, pop ratio ≤ 4.
TEST_CASE("gait-eval: matching plays each action button's graph clip through and resumes, within the limits",
          "[gait_eval][matching][action]") {
    set_simulation_float_mode();
    const AppConfig shipped = default_config();
    SimConfig config = shipped.sim;
    config.motion_source = MotionSourceSetting::matching;
    config.terrain_name = "flat";
    config.terrain = load_terrain("flat");
    const auto graph = std::make_shared<const MotionGraph>(build_default_motion_graph(config, shipped.graph_build));
    const char* labels[] = {"jump", "wave", "bow", "look_around"};
    const Button buttons[] = {Button::south, Button::east, Button::west, Button::north};
    for (int a = 0; a < 4; ++a) {
        for (const bool walking : {true, false}) {
            INFO(labels[a] << (walking ? " while walking" : " standing"));
            const int label = graph->label_index(labels[a]);
            REQUIRE(label >= 0);
            int clip_frames = -1;
            for (const GraphClip& c : graph->clips)
                if (((c.label_mask >> label) & 1u) && clip_frames < 0) clip_frames = c.frame_count;
            REQUIRE(clip_frames > 1);
            Simulation sim(config);
            attach_motion_graph(sim, graph, "default");
            TickInput in;
            in.left_y = walking ? static_cast<std::int16_t>(-0.6 * 32767) : 0;
            for (int tick = 0; tick < 480; ++tick) sim.step(in);
            REQUIRE(sim.state().matching.action == -1);
            int acting = 0, started = -1, ended = -1;
            for (int tick = 0; tick < 240 * 8; ++tick) {
                // Pressed for 3 ticks, then again 0.5 s later while the action plays.
                in.buttons = (tick < 3 || (tick >= 120 && tick < 123)) ? button_bit(buttons[a]) : 0u;
                sim.step(in);
                const std::int32_t action = sim.state().matching.action;
                if (action >= 0 && started < 0) started = tick;
                if (action < 0 && started >= 0 && ended < 0) ended = tick;
                acting += action >= 0 ? 1 : 0;
            }
            CHECK(started == 0);
            const double expected = (clip_frames - 1) * 240.0 / graph->frame_rate;
            CHECK(ended - started == acting);  // one action, not restarted by the second press
            CHECK(std::fabs(acting - expected) <= 240.0 / graph->frame_rate + 1.0);
            CHECK(sim.state().matching.action == -1);
            const MatchingDatabase* db = sim.matching_database();
            REQUIRE(db != nullptr);
            CHECK(sim.state().matching.frame < db->matched_frames);
        }
    }
    for (const char* terrain : {"flat", "stairs"}) {
        INFO("actions.prog on " << terrain);
        config.terrain_name = terrain;
        config.terrain = load_terrain(terrain);
        const GaitMetrics m = evaluate_gait(config, load_program(test::source_path("config/programs/actions.prog")), {}, graph);
        CHECK(m.motion_source == "matching");
        CHECK(m.max_joint_speed_deg_s < 1500.0);
        CHECK(m.penetration_mm <= 1.0);
        CHECK(m.foot_skate_mm <= 2.0);
        CHECK(m.pop_ratio <= 4.0);
    }
}

// A button held while the puppet switches into matching or graph mode (a live
// retune) is not a press there: it plays nothing until it is released and
// pressed again. Before, matching and the graph compared with the buttons of
// the last tick they had run (none here), so a held button started its action.
TEST_CASE("gait-eval: a button held across a switch into matching or the graph is not a press", "[gait_eval][matching][action]") {
    set_simulation_float_mode();
    const AppConfig shipped = default_config();
    SimConfig config = shipped.sim;
    config.terrain_name = "flat";
    config.terrain = load_terrain("flat");
    const auto graph = std::make_shared<const MotionGraph>(build_default_motion_graph(config, shipped.graph_build));
    for (const MotionSourceSetting source : {MotionSourceSetting::matching, MotionSourceSetting::graph}) {
        INFO((source == MotionSourceSetting::matching ? "into matching" : "into the graph"));
        SimConfig start = config;
        start.motion_source = MotionSourceSetting::gait;
        Simulation sim(start);
        attach_motion_graph(sim, graph, "default");
        TickInput in;
        in.left_y = static_cast<std::int16_t>(-0.6 * 32767);
        for (int tick = 0; tick < 240; ++tick) sim.step(in);
        in.buttons = button_bit(Button::south);  // jump, held down in gait mode
        for (int tick = 0; tick < 60; ++tick) sim.step(in);
        SimConfig next = start;
        next.motion_source = source;
        REQUIRE(sim.retune(next).ok());
        const auto acting = [&] {
            return source == MotionSourceSetting::matching ? sim.state().matching.action >= 0 : sim.state().graph.action_label >= 0;
        };
        int acted = 0;
        for (int tick = 0; tick < 240; ++tick) {
            sim.step(in);
            acted += acting() ? 1 : 0;
        }
        CHECK(acted == 0);
        in.buttons = 0;
        for (int tick = 0; tick < 10; ++tick) sim.step(in);
        in.buttons = button_bit(Button::south);
        for (int tick = 0; tick < 120; ++tick) {
            sim.step(in);
            acted += acting() ? 1 : 0;
        }
        CHECK(acted > 0);  // a real press still plays it
    }
}
