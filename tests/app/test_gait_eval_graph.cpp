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
