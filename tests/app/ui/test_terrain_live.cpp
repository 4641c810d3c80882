// Live terrain (docs/ui.md, "Terrain editor"): a terrain edit reaches the
// simulation at a tick boundary, the live pipeline records it as a configuration
// change, and replaying that recording gives the run's trace bit for bit, for
// generated edit sequences made with the terrain editor's own functions.
#include <catch2/catch.hpp>

#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "app/config/config.hpp"
#include "app/config/terrain_file.hpp"
#include "app/eval/replay.hpp"
#include "app/io/files.hpp"
#include "app/live/pipeline.hpp"
#include "app/ui/terrain_edit.hpp"

using namespace marionette;

namespace {
std::string temp_path(const std::string& name) {
    return (std::filesystem::temp_directory_path() / ("marionette_terrain_live_" + name)).string();
}

// One random edit of the terrain editor's kinds, centred within `reach` metres
// of (cx, cz): near the puppet, so it walks on what changed.
void random_edit(Terrain& t, std::mt19937& rng, float cx, float cz, float reach) {
    auto uniform = [&](float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); };
    const float x = cx + uniform(-reach, reach);
    const float z = cz + uniform(-reach, reach);
    const std::size_t pick = rng();
    switch (rng() % 9) {
        case 0: (void)ui::add_box(t, x, z, uniform(0.0f, 3.0f), uniform(-0.2f, 0.4f)); break;
        case 1: (void)ui::add_slope(t, x, z, uniform(0.0f, 3.0f), uniform(-0.2f, 0.4f)); break;
        case 2:
            if (!t.boxes.empty()) (void)ui::move_box(t, pick % t.boxes.size(), uniform(-1, 1), uniform(-1, 1), uniform(-0.2f, 0.2f));
            break;
        case 3: if (!t.boxes.empty()) (void)ui::resize_box(t, pick % t.boxes.size(), uniform(-2, 2), uniform(-2, 2)); break;
        case 4: if (!t.boxes.empty()) (void)ui::delete_box(t, pick % t.boxes.size()); break;
        case 5:
            if (!t.slopes.empty()) (void)ui::tilt_slope(t, pick % t.slopes.size(), uniform(-0.5f, 0.5f), uniform(-0.5f, 0.5f));
            break;
        case 6: if (!t.slopes.empty()) (void)ui::resize_slope(t, pick % t.slopes.size(), uniform(-2, 2), uniform(-2, 2)); break;
        case 7: if (!t.slopes.empty()) (void)ui::delete_slope(t, pick % t.slopes.size()); break;
        default: (void)ui::brush_heightfield(t, x, z, uniform(0.0f, 2.0f), uniform(-0.15f, 0.15f)); break;
    }
}

PipelineOptions virtual_run(const SimConfig& config, const std::string& program_text, std::uint64_t ticks) {
    PipelineOptions o;
    o.config = config;
    o.script = script_from_program(parse_stick_program(program_text, "walk.prog"), kSimulatedControllerHz, {});
    o.total_ticks = ticks;
    o.virtual_time = true;
    o.status_lines = false;
    return o;
}

PipelineResult run_quietly(PipelineOptions& o) {
    std::FILE* out = std::tmpfile();
    REQUIRE(out);
    o.out = out;
    const PipelineResult r = run_pipeline(o);
    std::fclose(out);
    return r;
}
}  // namespace

TEST_CASE("a terrain edit applies at the tick boundary: same states before it, the new ground after", "[ui][terrain_live]") {
    const SimConfig config = default_config().sim;
    SimConfig raised = config;
    (void)ui::add_box(raised.terrain, 0.0f, 0.0f, 40.0f, 0.3f);  // a platform under the whole walk
    TickInput forward{};
    forward.left_y = 32767;
    Simulation plain(config), edited(config);
    for (int k = 0; k < 1200; ++k) {
        if (k == 240) REQUIRE(edited.retune(raised).ok());
        plain.step(forward);
        edited.step(forward);
        INFO("tick " << k);
        if (k < 240) REQUIRE(hash_state(plain.state()) == hash_state(edited.state()));
    }
    CHECK(edited.terrain() == raised.terrain);
    CHECK(plain.terrain() == config.terrain);
    // Standing on the platform (the default terrain is the stairs: the plain run is on a step).
    const vec3 root = edited.state().root_position;
    INFO("root " << root.x << ", " << root.y << ", " << root.z << "; plain root y " << plain.state().root_position.y);
    CHECK(root.y == Approx(query_ground(raised.terrain, root.x, root.z).height).margin(0.01));
    CHECK(query_ground(raised.terrain, root.x, root.z).height > query_ground(config.terrain, root.x, root.z).height);
    CHECK(root.y > plain.state().root_position.y);
    // Back to the old ground: the tuning of the rest stays, only the ground changed.
    REQUIRE(edited.retune(config).ok());
    CHECK(edited.terrain() == config.terrain);
    // The tick rate and the puppet still cannot change live.
    SimConfig faster = raised;
    faster.tick_rate_hz = 120;
    CHECK(structure_unchanged(config, faster).problem() == "simulation.tick_rate_hz");
    CHECK(structure_unchanged(config, raised).ok());
}

TEST_CASE("an emptied terrain is recorded so that it reads back empty, not as the file it came from",
          "[ui][terrain_live]") {
    SimConfig config = default_config().sim;
    config.terrain = load_terrain("stairs");
    config.terrain_name = "stairs";
    SimConfig emptied = config;
    while (!emptied.terrain.boxes.empty()) REQUIRE(ui::delete_box(emptied.terrain, 0));
    while (!emptied.terrain.slopes.empty()) REQUIRE(ui::delete_slope(emptied.terrain, 0));
    REQUIRE(emptied.terrain.heightfield.nx < 2);
    const SimConfig read = apply_config_change(config, serialize_config(emptied), "emptied");
    CHECK(read.terrain == emptied.terrain);
}

TEST_CASE("generated terrain edits applied live are recorded and replay to the run's trace bit for bit",
          "[ui][terrain_live]") {
    const char* starts[] = {"flat", "stairs", "rubble", "hillside"};
    const std::string program = "hold 1s ly=1\ncircle 3s radius=1 turns=1\n";
    const std::uint64_t ticks = 4 * 240;
    std::mt19937 rng(1919);  // fixed seed
    for (int c = 0; c < 8; ++c) {
        SimConfig config = default_config().sim;
        config.terrain_name = starts[c % 4];
        config.terrain = load_terrain(config.terrain_name);
        PipelineOptions o = virtual_run(config, program, ticks);
        // 1 to 6 edits at increasing ticks, each a few edits of the editor's kinds
        // around where the puppet walks.
        SimConfig running = config;
        const int changes = 1 + static_cast<int>(rng() % 6);
        std::uint64_t at = 0;
        for (int e = 0; e < changes; ++e) {
            at += 1 + rng() % (ticks / static_cast<std::uint64_t>(changes) - 1);
            // The first change always raises a step where the puppet walks, so every case changes its walk.
            if (e == 0) (void)ui::add_box(running.terrain, 0.0f, 0.5f, 3.0f, 0.1f + 0.2f * static_cast<float>(rng() % 100) / 100.0f);
            const int edits = 1 + static_cast<int>(rng() % 4);
            for (int i = 0; i < edits; ++i) random_edit(running.terrain, rng, 0.0f, 1.0f, 2.5f);
            o.scheduled_changes.push_back({at, running});
        }
        o.trace_file = temp_path("run.csv");
        o.record_file = temp_path("run.mlog");
        const PipelineResult r = run_quietly(o);
        INFO("case " << c << " on " << starts[c % 4] << ", " << changes << " terrain changes");
        REQUIRE(r.ticks == ticks);

        const DecodedInputLog log = decode_input_log(read_binary_file(o.record_file), o.record_file);
        REQUIRE(log.config_changes.size() == o.scheduled_changes.size());
        for (size_t i = 0; i < log.config_changes.size(); ++i) {
            CHECK(log.config_changes[i].before_tick == o.scheduled_changes[i].before_tick);
            const SimConfig read = apply_config_change(config, log.config_changes[i].config_text, "recorded change");
            CHECK(read.terrain == o.scheduled_changes[i].config.terrain);
        }
        ReplayOptions ro;
        ro.trace_csv = temp_path("replay.csv");
        const ReplayResult replayed = replay_log(log, o.record_file, ro);
        CHECK(static_cast<size_t>(replayed.config_changes) == o.scheduled_changes.size());
        CHECK(replayed.final_hash == r.final_hash);
        CHECK(read_text_file(ro.trace_csv) == read_text_file(o.trace_file));

        // The edits mattered: the same walk without them ends elsewhere.
        PipelineOptions unedited = virtual_run(config, program, ticks);
        CHECK(run_quietly(unedited).final_hash != r.final_hash);
        for (const std::string& f : {ro.trace_csv, o.trace_file, o.record_file}) std::remove(f.c_str());
    }
}
