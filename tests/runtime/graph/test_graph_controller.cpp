// The motion-graph controller: path following, actions, attract mode, pose
// continuity, determinism and no allocation in the tick, on a small synthetic
// graph (tests/graph_fixture.hpp).
#include <catch2/catch.hpp>

#include <cmath>
#include <functional>

#include "runtime/math/det_math.hpp"
#include "runtime/graph/graph_controller.hpp"
#include "runtime/sim/simulation.hpp"
#include "runtime/sim/tick_input.hpp"
#include "tests/alloc_counter.hpp"
#include "tests/graph_fixture.hpp"
#include "tests/graph_path_check.hpp"

using namespace marionette;

namespace {

constexpr float kDt = 1.0f / 60.0f;

struct Run {
    const MotionGraph graph = test::make_locomotion_graph();
    GraphControllerConfig config;
    std::vector<quat> rotations, previous_rotations;
    std::vector<vec3> translations, previous_translations;
    double max_rotation_jump = 0.0, max_translation_jump = 0.0;

    Run() {
        config.max_speed = 1.2;
        config.horizon_s = 0.6;
    }
    // Runs `ticks` ticks with stick(t) and buttons(t); returns the final state.
    template <class Stick>
    GraphControllerState run(int ticks, Stick stick, GraphControllerState* start = nullptr) {
        GraphController controller(graph, config);
        GraphControllerState s = start ? *start : controller.initial_state();
        const size_t n = static_cast<size_t>(graph.joint_count());
        rotations.assign(n, quat_identity()), translations.assign(n, vec3(0.0f));
        REQUIRE(controller.pose(s, {rotations, translations}));
        for (int t = 0; t < ticks; ++t) {
            previous_rotations = rotations, previous_translations = translations;
            GraphControllerInput in = stick(t);
            in.dt = kDt;
            REQUIRE(controller.step(s, in, {rotations, translations}));
            for (size_t j = 0; j < n; ++j) {
                max_rotation_jump = std::max(max_rotation_jump, quat_angle_between(previous_rotations[j], rotations[j]));
                max_translation_jump =
                    std::max(max_translation_jump, static_cast<double>(glm::length(previous_translations[j] - translations[j])));
            }
            on_tick(controller, s, t);
        }
        return s;
    }
    std::function<void(GraphController&, const GraphControllerState&, int)> on_tick = [](auto&, auto&, int) {};
};

double heading_of(const GraphController& c, const GraphControllerState& s, std::span<const quat> rotations) {
    (void)c, (void)s;
    const vec3 f = quat_rotate(rotations[0], vec3(0.0f, 0.0f, 1.0f));
    return det::atan2(f.x, f.z);
}

}  // namespace

TEST_CASE("graph controller walks straight where the stick points", "[graph][controller]") {
    Run r;
    double sum_error = 0.0;
    int samples = 0;
    const double desired = det::kHalfPi;  // stick right: +X
    r.on_tick = [&](GraphController& c, const GraphControllerState& s, int t) {
        if (t < 180) return;  // two seconds to turn
        sum_error += std::abs(det::wrap_angle(heading_of(c, s, r.rotations) - desired));
        ++samples;
    };
    const GraphControllerState s = r.run(600, [](int) { GraphControllerInput in; in.stick_x = 1.0f; return in; });
    const double mean_error = sum_error / samples;
    INFO("mean heading error " << mean_error << " rad");
    CHECK(mean_error < 0.25);
    // It travelled along +X at roughly walking speed (1.2 units/s for 10 s less the turn).
    CHECK(r.translations[0].x > 6.0f);
    CHECK(std::abs(r.translations[0].z) < 3.0f);
    CHECK(s.transitions_taken > 10);
    CHECK(r.max_rotation_jump < 0.1);
    CHECK(r.max_translation_jump < 0.05);
}

TEST_CASE("graph controller follows a circle program", "[graph][controller]") {
    Run r;
    const double omega = 0.5;  // rad/s of the stick direction
    double sum_error = 0.0, max_error = 0.0;
    int samples = 0;
    r.on_tick = [&](GraphController& c, const GraphControllerState& s, int t) {
        if (t < 180) return;
        const double desired = det::wrap_angle(omega * t * kDt);
        const double e = std::abs(det::wrap_angle(heading_of(c, s, r.rotations) - desired));
        sum_error += e, max_error = std::max(max_error, e);
        ++samples;
    };
    r.run(1200, [&](int t) {
        GraphControllerInput in;
        const double a = omega * t * kDt;
        in.stick_x = static_cast<float>(det::sin(a));
        in.stick_y = static_cast<float>(-det::cos(a));
        return in;
    });
    INFO("mean " << sum_error / samples << " max " << max_error);
    CHECK(sum_error / samples < 0.45);  // decisions come every 0.3 s (edge + transition), so it lags
    CHECK(max_error < 1.0);
    CHECK(r.max_rotation_jump < 0.1);
    CHECK(r.max_translation_jump < 0.05);
}

TEST_CASE("a pressed action button reaches and plays its clip, then locomotion resumes", "[graph][controller]") {
    Run r;
    r.config.button_label[3] = r.graph.label_index("wave");
    const int wave_clip = r.graph.clip_index("wave");
    int ticks_in_wave = 0, first_wave_tick = -1;
    r.on_tick = [&](GraphController& c, const GraphControllerState& s, int t) {
        const GraphEdge& e = c.graph().edges[static_cast<size_t>(s.edge)];
        if (c.graph().nodes[static_cast<size_t>(e.from)].clip == wave_clip && e.kind == GraphEdgeKind::clip) {
            ++ticks_in_wave;
            if (first_wave_tick < 0) first_wave_tick = t;
        }
    };
    const GraphControllerState s = r.run(240, [](int t) {
        GraphControllerInput in;
        in.stick_y = -1.0f;
        if (t >= 30 && t < 36) in.buttons = 1u << 3;
        return in;
    });
    CHECK(first_wave_tick > 30);
    CHECK(first_wave_tick < 30 + 60);  // reached within a second
    CHECK(ticks_in_wave >= 9);         // the wave clip's edge (5 frames at 30 Hz) played through
    CHECK(s.actions_played == 1);
    CHECK(s.mode == GraphMotionMode::locomotion);
    CHECK(r.max_rotation_jump < 0.1);
}

TEST_CASE("attract mode starts after the idle time and is deterministic per seed", "[graph][controller]") {
    Run r;
    r.config.attract_after_s = 1.0;
    r.config.seed = 42;
    int first_attract = -1;
    r.on_tick = [&](GraphController&, const GraphControllerState& s, int t) {
        if (first_attract < 0 && s.mode == GraphMotionMode::attract) first_attract = t;
    };
    const auto idle = [](int) { return GraphControllerInput{}; };
    const GraphControllerState a = r.run(600, idle);
    CHECK(first_attract >= 58);  // 60 ticks of 1/60 s
    CHECK(first_attract <= 60);
    CHECK(a.transitions_taken > 5);
    const GraphControllerState b = r.run(600, idle);
    CHECK(a.rng == b.rng);
    CHECK(a.world_dx == b.world_dx);
    r.config.seed = 7;
    const GraphControllerState c = r.run(600, idle);
    CHECK(c.rng != a.rng);
    // Input ends it.
    const GraphControllerState d = r.run(30, [](int) { GraphControllerInput in; in.stick_x = 1.0f; return in; },
                                         const_cast<GraphControllerState*>(&a));
    CHECK(d.mode == GraphMotionMode::locomotion);
}

TEST_CASE("graph controller step never allocates and repeats bit for bit", "[graph][controller]") {
    const MotionGraph graph = test::make_locomotion_graph();
    GraphControllerConfig config;
    config.button_label[0] = graph.label_index("wave");
    config.attract_after_s = 2.0;
    GraphController controller(graph, config);
    std::vector<quat> r(2);
    std::vector<vec3> t(2);
    int refused = 0;  // counted, not checked, inside the loop: an assertion may allocate
    const auto drive = [&](GraphControllerState& s, int ticks) {
        for (int i = 0; i < ticks; ++i) {
            GraphControllerInput in;
            in.dt = kDt;
            if (i < 400) in.stick_x = static_cast<float>(det::sin(i * 0.01)), in.stick_y = -0.7f;
            if (i == 100) in.buttons = 1;
            if (!controller.step(s, in, {r, t})) ++refused;
        }
    };
    GraphControllerState a = controller.initial_state(), b = controller.initial_state();
    const std::uint64_t before = test::allocation_count();
    drive(a, 900);
    CHECK(test::allocation_count() == before);
    drive(b, 900);
    CHECK(refused == 0);
    CHECK(a.world_dx == b.world_dx);
    CHECK(a.world_dz == b.world_dz);
    CHECK(a.edge == b.edge);
    CHECK(a.edge_position == b.edge_position);
    CHECK(a.nodes_expanded == b.nodes_expanded);
    CHECK(a.actions_played == 1);
}

TEST_CASE("graph controller refuses a graph with a dead end", "[graph][controller]") {
    MotionGraph g = test::make_locomotion_graph();
    g.edges.erase(g.edges.begin() + 1, g.edges.begin() + 6);  // node 1's transitions
    index_edges(g);
    CHECK_THROWS_WITH(GraphController(g, GraphControllerConfig{}), Catch::Contains("no way out"));
}

TEST_CASE("a simulation driven by a motion graph walks, repeats its hashes and never allocates", "[graph][controller][simulation]") {
    const auto graph = std::make_shared<const MotionGraph>(test::make_locomotion_graph());
    const SimConfig config;
    GraphControllerConfig controller;
    controller.max_speed = 1.2;
    const auto run = [&](std::vector<std::uint64_t>& hashes) {
        Simulation sim(config);
        const std::uint64_t gait_hash = sim.clip_data_hash();
        sim.use_motion_graph(graph, controller, 0.5);
        CHECK(sim.clip_data_hash() != gait_hash);
        CHECK(sim.skeleton().joint_count() == 2);
        TickInput in{};
        in.left_x = static_cast<std::int16_t>(kStickScale);
        const std::uint64_t before = test::allocation_count();
        for (int t = 0; t < 1200; ++t) sim.step(in);
        CHECK(test::allocation_count() == before);
        for (int t = 0; t < 240; ++t) {
            sim.step(in);
            hashes.push_back(hash_state(sim.state()));
        }
        // Five seconds at 1.2 graph units/s × 0.5 m per unit, toward +X after the turn.
        CHECK(sim.state().root_position.x > 1.5f);
        CHECK(sim.state().motion_source == 1);
        CHECK_THROWS_WITH(sim.use_motion_graph(graph, controller, 0.5), Catch::Contains("before the first tick"));
    };
    std::vector<std::uint64_t> a, b;
    a.reserve(2000), b.reserve(2000);
    run(a);
    run(b);
    CHECK(a == b);
}

TEST_CASE("sliced path queries on the test graph reach the one-shot answer bit for bit", "[graph][controller][path]") {
    const MotionGraph g = test::make_locomotion_graph();
    const test::SlicedQueryStats stats = test::check_sliced_queries(g, {1, 2, 3, 7, 64});
    CHECK(stats.queries == static_cast<std::int64_t>(g.nodes.size() * g.labels.size()));
    CHECK(stats.found == stats.queries);  // the test graph is strongly connected
    CHECK(stats.max_pops > 3);            // budgets 1, 2 and 3 really slice
}

namespace {
// The fields that decide what the controller does next (the rest are counters).
void check_same_state(const GraphControllerState& a, const GraphControllerState& b) {
    CHECK(a.edge == b.edge);
    CHECK(a.edge_position == b.edge_position);
    CHECK(a.world_angle == b.world_angle);
    CHECK(a.world_dx == b.world_dx);
    CHECK(a.world_dz == b.world_dz);
    CHECK(a.mode == b.mode);
    CHECK(a.action_label == b.action_label);
    CHECK(a.action_search_pops == b.action_search_pops);
    CHECK(a.action_path_length == b.action_path_length);
    CHECK(a.action_path_next == b.action_path_next);
    CHECK(a.action_path == b.action_path);
    CHECK(a.search_depth == b.search_depth);
    CHECK(a.best_edge == b.best_edge);
    CHECK(a.nodes_expanded == b.nodes_expanded);
    CHECK(a.actions_played == b.actions_played);
    CHECK(a.rng == b.rng);
}
}  // namespace

TEST_CASE("an action query spread over ticks continues identically from a copied state", "[graph][controller]") {
    const MotionGraph graph = test::make_locomotion_graph();
    GraphControllerConfig config;
    config.max_speed = 1.2;
    config.max_nodes_per_tick = 2;  // the wave query takes several ticks
    config.button_label[1] = graph.label_index("wave");
    std::vector<quat> r(2);
    std::vector<vec3> t(2);
    const auto input = [](int tick) {
        GraphControllerInput in;
        in.dt = kDt;
        in.stick_x = static_cast<float>(det::sin(tick * 0.02));
        in.stick_y = -0.8f;
        if (tick == 50 || tick == 250) in.buttons = 1u << 1;
        return in;
    };
    GraphController original(graph, config), fresh(graph, config), shared(graph, config);
    GraphControllerState s = original.initial_state();
    int searching_ticks = 0, copies = 0;
    for (int tick = 0; tick < 480; ++tick) {
        if (s.mode == GraphMotionMode::find_action && s.action_search_pops > 0 && copies < 4) {
            // A copy taken mid-query, stepped by a fresh controller, and by one whose
            // scratch another state has just used, follows the original tick for tick.
            ++copies;
            GraphControllerState by_fresh = s, by_shared = s, other = shared.initial_state(), a = s;
            GraphController follow(graph, config);
            for (int k = 0; k < 60; ++k) {
                GraphControllerInput in = input(tick + k);
                in.buttons = static_cast<std::uint16_t>(in.buttons | (1u << 1));  // keeps `other` querying too
                GraphControllerInput plain = input(tick + k);
                REQUIRE(follow.step(a, plain, {r, t}));
                REQUIRE(fresh.step(by_fresh, plain, {r, t}));
                REQUIRE(shared.step(other, k % 7 == 0 ? in : plain, {r, t}));
                REQUIRE(shared.step(by_shared, plain, {r, t}));
            }
            check_same_state(a, by_fresh);
            check_same_state(a, by_shared);
        }
        if (s.mode == GraphMotionMode::find_action) ++searching_ticks;
        REQUIRE(original.step(s, input(tick), {r, t}));
    }
    CHECK(copies == 4);
    CHECK(searching_ticks >= 4);  // both queries took more than one tick
    CHECK(s.actions_played == 2);
}
