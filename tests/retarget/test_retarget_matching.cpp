// Motion matching on a database of the shared CMU clips (issue #14): subject 16's
// walk, run, turn and stop clips (ASF/AMC), retargeted onto the puppet as they
// load (the path `marionette graph build --asf 16.asf *.amc` takes), make the
// graph whose labelled locomotion clips are the matching database; gait-eval
// then drives `[motion] source = "matching"` with it over the shipped programs.
// Every target of the issue is asserted here on the shipped programs: distance
// ratio, start latency, heading error, penetration, pop ratio, joint speed
// < 1500 °/s and foot skate ≤ 2 mm (docs/motion-matching.md, "CMU database").
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "app/config/config.hpp"
#include "app/config/program_source.hpp"
#include "app/config/terrain_file.hpp"
#include "app/eval/gait_eval.hpp"
#include "app/graph/graph_files.hpp"
#include "app/graph/default_graph.hpp"
#include "app/graph/graph_rebuild.hpp"
#include "runtime/anim/local_to_model.hpp"
#include "runtime/gait/puppet.hpp"
#include "runtime/math/det_math.hpp"
#include "runtime/sim/simulation.hpp"
#include "tests/test_support.hpp"

using namespace marionette;

namespace {
std::shared_ptr<const MotionGraph> cmu16_graph(const std::string& dir, const AppConfig& app) {
    GraphSources sources;
    sources.asf = dir + "/cmu_amc_16/16.asf";
    for (const char* clip : {"16_11", "16_15", "16_17", "16_19", "16_33", "16_35", "16_41", "16_43", "16_57"})
        sources.clips.push_back(dir + "/cmu_amc_16/" + clip + ".amc");
    offline::GraphBuildParams params = graph_build_params(app.graph_build);
    params.threads = 1;
    const Skeleton puppet = make_puppet_skeleton(app.sim);
    const offline::ClipDatabase db = load_graph_sources(sources, params.analysis_rate_hz, &puppet);
    return std::make_shared<const MotionGraph>(build_graph_from_sources(db, sources, params, {}).graph);
}
}  // namespace

TEST_CASE("retarget: matching on the retargeted CMU clips follows the stick on flat, slope and stairs", "[retarget][matching]") {
    const std::string dir = test::mocap_dir();
    if (dir.empty()) return;  // skipped without the shared data (fails under CI=true)
    const AppConfig app = default_config();
    const std::shared_ptr<const MotionGraph> graph = cmu16_graph(dir, app);
    REQUIRE(graph->skeleton.joint_names == make_puppet_skeleton(app.sim).joint_names);
    SimConfig config = app.sim;
    config.motion_source = MotionSourceSetting::matching;
    for (const char* terrain : {"flat", "slope", "stairs"}) {
        config.terrain_name = terrain;
        config.terrain = load_terrain(terrain);
        for (const char* program : {"fast_walk", "circle", "run"}) {
            INFO(terrain << " " << program);
            const GaitMetrics m =
                evaluate_gait(config, load_program(test::source_path(std::string("config/programs/") + program + ".prog")), {}, graph);
            CHECK(m.motion_source == "matching");
            CHECK(m.distance_ratio_to_gait >= 0.9);  // measured 1.03–1.11
            CHECK(m.distance_ratio_to_gait <= 1.2);
            CHECK(m.start_latency_s >= 0.0);
            CHECK(m.start_latency_s <= 0.35);        // measured 0.083–0.229 s
            CHECK(m.heading_error_deg <= 10.0);      // measured ≤ 2.0° (−1 on circle: no moving hold)
            CHECK(m.penetration_mm <= 1.0);          // measured ≤ 0.002 mm
            // Target ≤ 2 mm: measured ≤ 0.35 mm since the pinned reach (a pin is aimed at
            // through the soft reach's pre-image); 2.1 mm on flat fast_walk before it.
            CHECK(m.foot_skate_mm <= 2.0);
            CHECK(m.pop_ratio <= 4.0);               // measured 1.24–1.93 (3.7–21.7 with the clip's knee as pole)
            // Target < 1500 °/s: measured 815–1,495 (920–2,113 before the feet-over-risers
            // hold and the soft reach; 4,939–40,045 with the clip's knee as pole).
            CHECK(m.max_joint_speed_deg_s < 1500.0);
        }
    }
}

// After a stop the puppet stands still: with the stick at rest, a clip that
// ends at rest holds its last pose, and the search does not jump a few frames
// back (before, it looped three frames of the stop's end for seconds, 371 ↔ 372
// and 546 ↔ 552 on this database, the feet sliding by the loop's root motion).
// Generated stops (fixed seed): stick at a random angle and deflection 0.4–1
// for 1–3 s, then released for 4 s; over the last 1.5 s no joint moves more
// than 2 mm and no jump happens.
TEST_CASE("retarget: matching on the CMU clips stands still after generated stops", "[retarget][matching]") {
    const std::string dir = test::mocap_dir();
    if (dir.empty()) return;  // skipped without the shared data (fails under CI=true)
    set_simulation_float_mode();  // the tick's float mode, as every command sets it
    const AppConfig app = default_config();
    const std::shared_ptr<const MotionGraph> graph = cmu16_graph(dir, app);
    SimConfig config = app.sim;
    config.motion_source = MotionSourceSetting::matching;
    std::uint32_t seed = 7u;
    auto next = [&] { seed = seed * 1664525u + 1013904223u; return static_cast<double>(seed >> 8) / 16777216.0; };
    for (int c = 0; c < 8; ++c) {
        const double angle = 6.283185307179586 * next(), deflection = 0.4 + 0.6 * next();
        const int walk_ticks = 240 + static_cast<int>(480.0 * next());
        INFO("case " << c << ": angle " << angle << " rad, deflection " << deflection << ", " << walk_ticks << " ticks");
        Simulation sim(config);
        sim.use_motion_graph(graph, GraphControllerConfig{}, 1.0);
        TickInput walk{};
        walk.left_x = static_cast<std::int16_t>(32767.0 * deflection * det::sin(angle));
        walk.left_y = static_cast<std::int16_t>(32767.0 * deflection * det::cos(angle));
        for (int t = 0; t < walk_ticks; ++t) sim.step(walk);
        const TickInput rest{};
        for (int t = 0; t < 600; ++t) sim.step(rest);
        const PuppetState before = sim.state();
        REQUIRE(before.matching_active == 1);
        double moved = 0.0;
        for (int t = 0; t < 360; ++t) {
            sim.step(rest);
            for (int j = 0; j < before.joint_count; ++j) {
                const vec3 d = sim.state().model_positions[static_cast<size_t>(j)] - before.model_positions[static_cast<size_t>(j)];
                moved = std::max(moved, static_cast<double>(std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z)));
            }
        }
        INFO("frame " << before.matching.frame << " → " << sim.state().matching.frame << ", joints moved up to " << moved * 1000.0 << " mm");
        CHECK(sim.state().matching.jumps == before.matching.jumps);
        CHECK(moved < 2e-3);  // measured up to 1.01 mm (a knee settling sideways once, case 3)
    }
}

// Matching's knee pole is the thigh's frame's +Z (FootPlacementJob::thigh_pole,
// branch matching4): that assumes +Z of the thigh is the kneecap's side on the
// puppet's skeleton, for the puppet's own clips and for clips retargeted onto
// it. Checked on every frame of both databases' clips and on generated poses
// between them (fixed seed: two random frames nlerped at a random weight, as an
// inertialized jump shows): wherever a knee is bent by ≥ 5°, the knee lies on the
// thigh's +Z side of the hip–ankle line.
namespace {
struct KneeSide {
    double least = 2.0;  // least cos between (knee − hip–ankle midpoint) and the thigh's +Z
    double least_deep = 2.0;  // the same where the knee is bent ≥ 20°
    int bent = 0;             // legs bent ≥ 5° checked
};

void check_knees(const MotionGraph& graph, const std::vector<quat>& rotations, const std::vector<vec3>& translations,
                 KneeSide& side) {
    const size_t n = static_cast<size_t>(graph.joint_count());
    std::vector<quat> model_rotations(n);
    std::vector<vec3> model_positions(n);
    REQUIRE(LocalToModelJob{graph.skeleton.parents, {rotations, translations}, {model_rotations, model_positions}}.run());
    for (const int ankle : {graph.left_foot, graph.right_foot}) {
        const int knee = graph.skeleton.parents[static_cast<size_t>(ankle)];
        const int hip = graph.skeleton.parents[static_cast<size_t>(knee)];
        const vec3 h = model_positions[static_cast<size_t>(hip)], k = model_positions[static_cast<size_t>(knee)],
                   a = model_positions[static_cast<size_t>(ankle)];
        const vec3 thigh = glm::normalize(k - h), shin = glm::normalize(a - k);
        if (glm::dot(thigh, shin) > std::cos(5.0 * 3.14159265358979 / 180.0)) continue;
        const vec3 off = glm::normalize(k - 0.5f * (h + a));
        const vec3 z = quat_rotate(model_rotations[static_cast<size_t>(hip)], vec3(0.0f, 0.0f, 1.0f));
        side.least = std::min(side.least, static_cast<double>(glm::dot(off, z)));
        if (glm::dot(thigh, shin) < std::cos(20.0 * 3.14159265358979 / 180.0))
            side.least_deep = std::min(side.least_deep, static_cast<double>(glm::dot(off, z)));
        ++side.bent;
    }
}

KneeSide knee_sides(const MotionGraph& graph) {
    KneeSide side;
    const size_t n = static_cast<size_t>(graph.joint_count());
    const size_t frames = graph.rotations.size() / n;
    REQUIRE(graph.left_foot >= 0);
    REQUIRE(graph.right_foot >= 0);
    for (size_t f = 0; f < frames; ++f)
        check_knees(graph, {graph.rotations.begin() + static_cast<std::ptrdiff_t>(f * n), graph.rotations.begin() + static_cast<std::ptrdiff_t>((f + 1) * n)},
                    {graph.translations.begin() + static_cast<std::ptrdiff_t>(f * n), graph.translations.begin() + static_cast<std::ptrdiff_t>((f + 1) * n)}, side);
    std::uint32_t seed = 1757u;
    auto next = [&] { seed = seed * 1664525u + 1013904223u; return seed >> 8; };
    std::vector<quat> rotations(n);
    std::vector<vec3> translations(n);
    for (int c = 0; c < 1000; ++c) {
        const size_t f0 = next() % frames, f1 = next() % frames;
        const float w = static_cast<float>(next()) / 16777216.0f;
        for (size_t j = 0; j < n; ++j) {
            const quat q0 = graph.rotations[f0 * n + j];
            quat q1 = graph.rotations[f1 * n + j];
            if (q0.w * q1.w + q0.x * q1.x + q0.y * q1.y + q0.z * q1.z < 0.0f) q1 = -q1;
            rotations[j] = quat_normalize(q0 * (1.0f - w) + q1 * w);
            translations[j] = graph.translations[f0 * n + j] * (1.0f - w) + graph.translations[f1 * n + j] * w;
        }
        check_knees(graph, rotations, translations, side);
    }
    return side;
}
}  // namespace

TEST_CASE("retarget: the thigh's +Z is the kneecap's side on the puppet's own and the retargeted CMU clips", "[retarget][matching][knee]") {
    // The kneecap's side is cos > 0. Measured (least cos over legs bent ≥ 5°;
    // ≥ 20°): default 0.446 (0.446) over 6,806 legs, CMU 16 0.238 (0.597) over
    // 3,279: the thigh's twist leaves +Z up to ~76° off the plane the knee bends
    // in, never on the other side.
    const AppConfig app = default_config();
    const KneeSide own = knee_sides(build_default_motion_graph(app.sim, app.graph_build));
    INFO("default database: " << own.bent << " bent legs, least cos " << own.least << " (bent >= 20 deg: " << own.least_deep << ")");
    CHECK(own.bent > 1000);
    CHECK(own.least > 0.2);
    CHECK(own.least_deep > 0.2);
    const std::string dir = test::mocap_dir();
    if (dir.empty()) return;  // skipped without the shared data (fails under CI=true)
    const KneeSide cmu = knee_sides(*cmu16_graph(dir, app));
    INFO("CMU 16: " << cmu.bent << " bent legs, least cos " << cmu.least << " (bent >= 20 deg: " << cmu.least_deep << ")");
    CHECK(cmu.bent > 1000);
    CHECK(cmu.least > 0.2);
    CHECK(cmu.least_deep > 0.5);
}
