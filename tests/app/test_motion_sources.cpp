// [motion] source: the gait, the motion graph, and the graph with procedural
// foot placement (graph_feet), and live changes between them, which cross-fade
// instead of popping. Driven by the embedded default graph, whose skeleton is
// the puppet's, so the sources can blend.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <memory>

#include "app/graph/default_graph.hpp"
#include "app/graph/graph_files.hpp"
#include "app/config/terrain_file.hpp"
#include "runtime/gait/puppet.hpp"
#include "runtime/sim/simulation.hpp"
#include "tests/graph_fixture.hpp"

using namespace marionette;

namespace {

std::shared_ptr<const MotionGraph> default_graph() {
    static const auto graph = std::make_shared<const MotionGraph>(build_default_motion_graph(SimConfig{}, GraphBuildConfig{}));
    return graph;
}

SimConfig with_source(SimConfig c, MotionSourceSetting source) {
    c.motion_source = source;
    return c;
}

TickInput stick(float x, float y) {
    TickInput in;
    in.left_x = static_cast<std::int16_t>(x * kStickScale);
    in.left_y = static_cast<std::int16_t>(y * kStickScale);
    return in;
}

// Largest distance any joint moves in one tick, over `ticks` ticks of `input`.
struct StepWatch {
    double worst_joint_m = 0.0;
    double worst_root_m = 0.0;
    void step(Simulation& sim, const TickInput& input) {
        const PuppetState before = sim.state();
        sim.step(input);
        const PuppetState& now = sim.state();
        for (int j = 0; j < now.joint_count; ++j) {
            const size_t i = static_cast<size_t>(j);
            worst_joint_m = std::max(worst_joint_m, static_cast<double>(glm::length(now.model_positions[i] - before.model_positions[i])));
        }
        worst_root_m = std::max(worst_root_m, static_cast<double>(glm::length(now.root_position - before.root_position)));
    }
};

}  // namespace

TEST_CASE("motion sources: auto picks the graph when one is attached, the gait otherwise", "[motion_source]") {
    const SimConfig config;
    REQUIRE(config.motion_source == MotionSourceSetting::automatic);
    Simulation gait_only(config);
    CHECK(gait_only.state().motion_source == kSourceGait);
    CHECK(gait_only.state().graph_attached == 0);
    Simulation with_graph(config);
    attach_motion_graph(with_graph, default_graph());
    CHECK(with_graph.graph_matches_puppet());
    CHECK(with_graph.state().motion_source == kSourceGraph);
    Simulation told_gait(with_source(config, MotionSourceSetting::gait));
    attach_motion_graph(told_gait, default_graph());
    CHECK(told_gait.state().motion_source == kSourceGait);
    CHECK(told_gait.state().graph_attached == 1);
    CHECK(resolve_motion_source(with_source(config, MotionSourceSetting::graph_feet), false) == kSourceGait);
    CHECK(resolve_motion_source(with_source(config, MotionSourceSetting::graph_feet), true) == kSourceGraphFeet);
}

TEST_CASE("motion sources: a live change cross-fades over crossfade_s without a pop, both ways", "[motion_source]") {
    SimConfig config;
    config.tick_rate_hz = 240;
    config.motion_crossfade_s = 0.4f;
    const auto graph = default_graph();

    // The jumps a source makes on its own, walking: the bound a fade must keep to.
    auto own_worst = [&](MotionSourceSetting source) {
        Simulation sim(with_source(config, source));
        attach_motion_graph(sim, graph);
        StepWatch w;
        for (int k = 0; k < 240 * 4; ++k) w.step(sim, stick(0.0f, -0.6f));
        return w.worst_joint_m;
    };
    const double gait_worst = own_worst(MotionSourceSetting::gait);
    const double graph_worst = own_worst(MotionSourceSetting::graph);
    INFO("gait alone " << gait_worst << " m/tick, graph alone " << graph_worst << " m/tick");

    Simulation sim(with_source(config, MotionSourceSetting::gait));
    attach_motion_graph(sim, graph);
    StepWatch before_switch;
    for (int k = 0; k < 240 * 2; ++k) before_switch.step(sim, stick(0.0f, -0.6f));
    const vec3 root_before = sim.state().root_position;
    REQUIRE(glm::length(root_before) > 1.0f);  // it walked

    REQUIRE(sim.retune(with_source(config, MotionSourceSetting::graph)).ok());
    CHECK(sim.state().motion_source == kSourceGraph);
    CHECK(sim.state().fade.from == kSourceGait);
    CHECK(sim.state().fade.duration == Approx(0.4f));
    StepWatch during;
    int fade_ticks = 0;
    while (sim.state().fade.duration > 0.0f && fade_ticks < 1000) {
        during.step(sim, stick(0.0f, -0.6f));
        ++fade_ticks;
    }
    CHECK(fade_ticks >= 96);  // 0.4 s at 240 Hz (elapsed sums float ticks, so one more may round in)
    CHECK(fade_ticks <= 97);
    INFO("gait → graph fade: " << during.worst_joint_m << " m/tick, root " << during.worst_root_m);
    CHECK(during.worst_joint_m < 1.5 * std::max(gait_worst, graph_worst) + 0.005);
    CHECK(during.worst_root_m < 0.03);
    // The graph took over where the gait was: it started within a tick's walk of it.
    CHECK(glm::length(vec2(sim.state().root_position.x - root_before.x, sim.state().root_position.z - root_before.z)) < 1.0f);

    StepWatch on_graph;
    for (int k = 0; k < 240 * 2; ++k) on_graph.step(sim, stick(0.0f, -0.6f));
    REQUIRE(sim.retune(with_source(config, MotionSourceSetting::gait)).ok());
    CHECK(sim.state().motion_source == kSourceGait);
    StepWatch back;
    for (int k = 0; k < 120; ++k) back.step(sim, stick(0.0f, -0.6f));
    INFO("graph → gait fade: " << back.worst_joint_m << " m/tick");
    CHECK(back.worst_joint_m < 1.5 * std::max(gait_worst, graph_worst) + 0.005);
    CHECK(sim.state().fade.duration == 0.0f);
    // After it, the gait walks on from where the graph left the puppet.
    const vec3 at = sim.state().root_position;
    for (int k = 0; k < 240; ++k) sim.step(stick(0.0f, -0.6f));
    CHECK(glm::length(sim.state().root_position - at) > 0.5f);
}

TEST_CASE("motion sources: reversing a running fade runs it backwards (no jump)", "[motion_source]") {
    SimConfig config;
    config.motion_crossfade_s = 0.5f;
    Simulation sim(with_source(config, MotionSourceSetting::gait));
    attach_motion_graph(sim, default_graph());
    for (int k = 0; k < 240; ++k) sim.step(stick(0.3f, -0.5f));
    REQUIRE(sim.retune(with_source(config, MotionSourceSetting::graph)).ok());
    for (int k = 0; k < 30; ++k) sim.step(stick(0.3f, -0.5f));
    const float elapsed = sim.state().fade.elapsed;
    REQUIRE(sim.retune(with_source(config, MotionSourceSetting::gait)).ok());
    CHECK(sim.state().motion_source == kSourceGait);
    CHECK(sim.state().fade.from == kSourceGraph);
    CHECK(sim.state().fade.elapsed == Approx(0.5f - elapsed));
    StepWatch w;
    for (int k = 0; k < 240; ++k) w.step(sim, stick(0.3f, -0.5f));
    CHECK(w.worst_joint_m < 0.05);
}

TEST_CASE("motion sources: refusals name motion.source and change nothing", "[motion_source]") {
    const SimConfig config;
    SECTION("no graph attached") {
        Simulation sim(config);
        const Outcome refused = sim.retune(with_source(config, MotionSourceSetting::graph));
        CHECK_FALSE(refused.ok());
        const std::string& why = refused.problem();
        CHECK(why.rfind("motion.source", 0) == 0);
        CHECK(why.find("no motion graph") != std::string::npos);
        CHECK(sim.state().motion_source == kSourceGait);
        CHECK(sim.config().motion_source == MotionSourceSetting::automatic);
        CHECK(sim.motion_source_allowed(with_source(config, MotionSourceSetting::gait)).ok());
    }
    SECTION("a graph of another skeleton cannot blend with the gait") {
        Simulation sim(config);
        sim.use_motion_graph(std::make_shared<const MotionGraph>(test::make_locomotion_graph()), GraphControllerConfig{}, 1.0);
        CHECK_FALSE(sim.graph_matches_puppet());
        CHECK(sim.state().motion_source == kSourceGraph);
        CHECK(sim.skeleton().joint_count() == 2);
        const Outcome refused = sim.retune(with_source(config, MotionSourceSetting::gait));
        CHECK_FALSE(refused.ok());
        const std::string& why = refused.problem();
        CHECK(why.find("skeleton is not the puppet's") != std::string::npos);
        CHECK(sim.state().motion_source == kSourceGraph);
        // It has no legs, so graph_feet is refused too.
        CHECK(sim.retune(with_source(config, MotionSourceSetting::graph_feet)).problem().find("graph_feet") != std::string::npos);
        CHECK_THROWS_AS(
            [&] {
                Simulation feet(with_source(config, MotionSourceSetting::graph_feet));
                feet.use_motion_graph(std::make_shared<const MotionGraph>(test::make_locomotion_graph()),
                                      GraphControllerConfig{}, 1.0);
            }(),
            std::invalid_argument);
    }
}

TEST_CASE("motion sources: graph_feet pins contacting feet and stands them on the terrain", "[motion_source]") {
    const char* terrains[] = {"flat", "stairs", "slope"};
    for (const char* terrain_name : terrains) {
        INFO("terrain " << terrain_name);
        SimConfig config = with_source(SimConfig{}, MotionSourceSetting::graph_feet);
        config.terrain = load_terrain(terrain_name);
        config.terrain_name = terrain_name;
        Simulation sim(config);
        attach_motion_graph(sim, default_graph());
        REQUIRE(sim.state().motion_source == kSourceGraphFeet);
        const MotionGraph& g = *default_graph();
        const int ankles[2] = {g.left_foot, g.right_foot};
        REQUIRE(ankles[0] >= 0);
        REQUIRE(ankles[1] >= 0);
        double worst_pinned_drift = 0.0, worst_ankle_below = -1e9, worst_body_gap = 0.0;
        vec3 pinned_at[2];
        bool was_pinned[2] = {false, false};
        int pinned_ticks = 0;
        const float ankle_height = config.ankle_height;
        for (int k = 0; k < 240 * 8; ++k) {
            // Walk along −Z (up the stairs / slope), curving a little.
            sim.step(stick(k < 240 * 4 ? 0.0f : 0.4f, -0.7f));
            const PuppetState& s = sim.state();
            for (int i = 0; i < 2; ++i) {
                const FootPin& pin = s.feet.feet[static_cast<size_t>(i)];
                const vec3 a = s.model_positions[static_cast<size_t>(ankles[i])];
                const bool pinned = pin.contact == 1;
                if (pinned && !was_pinned[i]) pinned_at[i] = a;
                if (pinned) {
                    ++pinned_ticks;
                    worst_pinned_drift = std::max(worst_pinned_drift, static_cast<double>(glm::length(a - pinned_at[i])));
                    // A planted ankle stands about its height above the ground under it.
                    const float ground = query_ground(sim.terrain(), a.x, a.z).height;
                    worst_ankle_below = std::max(worst_ankle_below, static_cast<double>(ground + 0.5f * ankle_height - a.y));
                }
                was_pinned[i] = pinned;
            }
            const vec3 pelvis = s.model_positions[0];
            const float under = query_ground(sim.terrain(), pelvis.x, pelvis.z).height;
            worst_body_gap = std::max(worst_body_gap, static_cast<double>(std::fabs(s.feet.body_offset - under)));
        }
        INFO("pinned drift " << worst_pinned_drift << " m, ankle below " << worst_ankle_below << " m, body gap "
                             << worst_body_gap << " m over " << pinned_ticks << " pinned foot-ticks");
        CHECK(pinned_ticks > 240);               // the feet were planted a good part of the time
        CHECK(worst_pinned_drift < 0.002);       // a pinned foot stays put (the IK reaches it)
        CHECK(worst_ankle_below < 0.0);          // and is not sunk into the ground
        CHECK(worst_body_gap < 0.35);            // the body follows the ground's height
    }
}

TEST_CASE("motion sources: graph_feet is deterministic and its state is in the hash", "[motion_source]") {
    SimConfig config = with_source(SimConfig{}, MotionSourceSetting::graph_feet);
    config.terrain = load_terrain("stairs");
    config.terrain_name = "stairs";
    auto run = [&](MotionSourceSetting switch_to) {
        Simulation sim(config);
        attach_motion_graph(sim, default_graph());
        for (int k = 0; k < 600; ++k) {
            if (k == 300) REQUIRE(sim.retune(with_source(config, switch_to)).ok());
            sim.step(stick(0.2f, -0.8f));
        }
        return hash_state(sim.state());
    };
    CHECK(run(MotionSourceSetting::gait) == run(MotionSourceSetting::gait));
    CHECK(run(MotionSourceSetting::gait) != run(MotionSourceSetting::graph));
}
