// Golden per-tick traces for the shipped programs: the committed files in
// tests/golden/ were written by `marionette replay LOG --trace` (see
// docs/input-log.md, "Golden traces", to regenerate after an intended change).
// CI runs this in the optimised and the asan build, so both must produce the
// same bits as the committed run.
#include <catch2/catch.hpp>

#include <sstream>

#include "app/config/config.hpp"
#include "app/config/program_source.hpp"
#include "app/eval/replay.hpp"
#include "tests/test_support.hpp"

using namespace marionette;

namespace {
std::vector<std::uint8_t> record(const std::string& program_spec, const SimConfig& config) {
    const StickProgram program = load_program(program_spec);
    Simulation sim(config);
    InputLogHeader header;
    header.tick_rate_hz = static_cast<std::uint32_t>(config.tick_rate_hz);
    header.clip_data_hash = sim.clip_data_hash();
    header.config_text = serialize_config(config);
    return encode_input_log(header, render_stick_program(program, config.tick_rate_hz), 60);
}

std::vector<std::string> lines_of(const std::string& text) {
    std::vector<std::string> lines;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
}
}  // namespace

TEST_CASE("replays of the shipped programs match the committed golden traces", "[golden]") {
    const SimConfig config = default_config().sim;
    for (const std::string name : {"stand_still", "walk_stop", "circle", "demo", "slow_walk", "fast_walk", "run", "start_stop",
                                   "full_circle", "reversals", "stop_mid_step"}) {
        INFO("program " << name);
        const DecodedInputLog log = decode_input_log(record("builtin:" + name, config), name);
        REQUIRE(log.warning.empty());
        const std::string trace_path = "golden_" + name + ".csv";
        ReplayOptions options;
        options.trace_csv = trace_path;
        options.keep_tick_hashes = true;
        const ReplayResult result = replay_log(log, name, options);
        const std::vector<std::string> actual = lines_of(test::read_text_file(trace_path));
        const std::vector<std::string> golden =
            lines_of(test::read_text_file(test::source_path("tests/golden/" + name + ".trace.csv")));
        REQUIRE(actual.size() == golden.size());
        for (size_t i = 0; i < golden.size(); ++i) {
            if (actual[i] != golden[i]) {
                INFO("first difference at line " << i + 1 << "\n  golden: " << golden[i] << "\n  actual: " << actual[i]);
                REQUIRE(actual[i] == golden[i]);
            }
        }
        CHECK(result.tick_hashes.size() == golden.size() - 1);
    }
}

TEST_CASE("replaying the same log twice gives identical hashes at every tick", "[golden]") {
    const DecodedInputLog log = decode_input_log(record("builtin:circle", default_config().sim), "circle");
    ReplayOptions options;
    options.keep_tick_hashes = true;
    const ReplayResult a = replay_log(log, "circle", options);
    const ReplayResult b = replay_log(log, "circle", options);
    REQUIRE(a.tick_hashes.size() == log.ticks.size());
    CHECK(a.tick_hashes == b.tick_hashes);
    CHECK(a.final_hash == b.final_hash);
    CHECK(a.distance_m > 5.0);
}

TEST_CASE("a log recorded with another configuration replays with that configuration", "[golden]") {
    SimConfig slow = default_config().sim;
    slow.max_speed = 1.0f;
    const DecodedInputLog log = decode_input_log(record("builtin:walk_stop", slow), "slow");
    const ReplayResult slow_run = replay_log(log, "slow", {});
    const DecodedInputLog normal = decode_input_log(record("builtin:walk_stop", default_config().sim), "normal");
    const ReplayResult normal_run = replay_log(normal, "normal", {});
    CHECK(slow_run.distance_m < normal_run.distance_m);
    CHECK(slow_run.final_hash != normal_run.final_hash);
}

TEST_CASE("a log whose clip data differ from this build is refused", "[golden]") {
    std::vector<std::uint8_t> bytes = record("builtin:stand_still", default_config().sim);
    DecodedInputLog log = decode_input_log(bytes, "x");
    log.header.clip_data_hash ^= 1;
    CHECK_THROWS_WITH(replay_log(log, "x.mlog", {}), Catch::Contains("different clip data"));
}

// ---- golden traces with the motion graph ---------------------------------------
// The embedded default graph drives these (graph, graph_feet on stairs, and a log
// whose recorded configuration changes switch gait → graph_feet → gait live, so
// the cross-fades are in the trace). The graph's bytes do not depend on the BLAS
// kernel (docs/determinism.md, "Graph builds"), so a default graph whose hash is
// not tests/golden/default_graph.hash's is a failure, as is any trace difference.
// MARIONETTE_WRITE_GOLDEN=1 writes the traces and the hash into the working
// directory (scripts/update-golden.sh copies them over).
#include <cstdlib>
#include <fstream>
#include <string_view>

#include <fmt/format.h>
#include <xxhash.h>

#include "app/graph/default_graph.hpp"
#include "app/graph/graph_files.hpp"

namespace {
struct GraphGolden {
    const char* name;
    std::string program;                 // load_program spec
    const char* source;                  // [motion] source of the recording
    const char* terrain;
    std::vector<std::pair<std::uint64_t, const char*>> switches;  // before tick → [motion] source
};

std::string source_config(const char* source) { return fmt::format("[motion]\nsource = \"{}\"\n", source); }
}  // namespace

TEST_CASE("replays driven by the default motion graph match the committed golden traces", "[golden][golden_graph]") {
    const bool write = std::getenv("MARIONETTE_WRITE_GOLDEN") != nullptr;
    const AppConfig shipped = default_config();
    SimConfig base = shipped.sim;  // stairs, as shipped
    // One builder thread (the bytes do not depend on it; scripts/check-blas.sh builds
    // with 1–3): the build then starts no thread, and under qemu user-mode emulation
    // (scripts/check-aarch64.sh) glibc's pthread_create was seen to spin for minutes.
    const auto graph = std::make_shared<const MotionGraph>(build_default_motion_graph(base, shipped.graph_build, 1));
    const std::vector<std::uint8_t> graph_bytes = serialize_motion_graph(*graph);
    const std::string graph_hash = fmt::format("{:016x}", XXH64(graph_bytes.data(), graph_bytes.size(), 0));
    const std::string hash_path = test::source_path("tests/golden/default_graph.hash");
    std::string golden_hash;
    if (std::ifstream in(hash_path); in) in >> golden_hash;
    if (write) std::ofstream("default_graph.hash") << graph_hash << "\n";
    if (!write) {
        INFO("this build's default graph (" << graph_hash << ") is not the one the golden traces were made with ("
                                            << golden_hash << ", tests/golden/default_graph.hash)");
        REQUIRE(graph_hash == golden_hash);
    }

    const GraphGolden cases[] = {
        {"graph_actions", test::source_path("config/programs/actions.prog"), "graph", "flat", {}},
        {"graph_feet_circle_stairs", "builtin:circle", "graph_feet", "stairs", {}},
        {"graph_switch_stairs", "builtin:demo", "gait", "stairs", {{480, "graph_feet"}, {1440, "gait"}}},
        // Motion matching (docs/motion-matching.md) on the database the default
        // graph's locomotion clips make: the whole demo on stairs (search, jumps,
        // inertialization, foot placement and the look-ahead lift), and live
        // switches gait → matching → graph_feet → matching → gait on the slope.
        {"matching_demo_stairs", "builtin:demo", "matching", "stairs", {}},
        {"matching_switch_slope",
         "builtin:demo",
         "gait",
         "slope",
         {{480, "matching"}, {1440, "graph_feet"}, {2400, "matching"}, {3360, "gait"}}},
    };
    for (const GraphGolden& c : cases) {
        INFO("golden " << c.name);
        SimConfig config = config_from_text(source_config(c.source) + fmt::format("[terrain]\nname = \"{}\"\n", c.terrain), c.name).sim;
        // Record: the simulation as the live pipeline runs it, config changes at tick boundaries.
        const StickProgram program = load_program(c.program);
        const std::vector<TickInput> ticks = render_stick_program(program, config.tick_rate_hz);
        Simulation sim(config);
        attach_motion_graph(sim, graph);
        InputLogHeader header;
        header.tick_rate_hz = static_cast<std::uint32_t>(config.tick_rate_hz);
        header.clip_data_hash = sim.clip_data_hash();
        header.config_text = serialize_config(config);
        DecodedInputLog log = decode_input_log(encode_input_log(header, ticks, 60), c.name);
        std::vector<std::uint64_t> recorded;
        size_t next_switch = 0;
        SimConfig running = config;
        for (std::uint64_t k = 0; k < ticks.size(); ++k) {
            if (next_switch < c.switches.size() && c.switches[next_switch].first == k) {
                const std::string text = source_config(c.switches[next_switch].second);
                running = apply_config_change(running, text, c.name);
                REQUIRE(sim.retune(running).ok());
                log.config_changes.push_back({k, serialize_config(running)});
                ++next_switch;
            }
            sim.step(ticks[k]);
            recorded.push_back(hash_state(sim.state()));
        }
        if (std::string_view(c.name).starts_with("matching")) {
            // The trace covers searches and inertialized jumps, not one clip played through.
            INFO("matching searches " << sim.state().matching.searches << ", jumps " << sim.state().matching.jumps);
            CHECK(sim.state().matching.jumps >= 10);
            CHECK(sim.state().matching.searches > sim.state().matching.jumps);
        }
        const std::string trace_path = fmt::format("golden_{}.csv", c.name);
        ReplayOptions options;
        options.trace_csv = trace_path;
        options.keep_tick_hashes = true;
        options.graph = graph;
        const ReplayResult result = replay_log(log, c.name, options);
        REQUIRE(result.tick_hashes == recorded);  // the replay is the recording, tick for tick
        CHECK(result.config_changes == static_cast<int>(c.switches.size()));
        CHECK(result.distance_m > 1.0);
        if (write) continue;
        const std::vector<std::string> actual = lines_of(test::read_text_file(trace_path));
        const std::vector<std::string> golden =
            lines_of(test::read_text_file(test::source_path(fmt::format("tests/golden/{}.trace.csv", c.name))));
        REQUIRE(actual.size() == golden.size());
        for (size_t i = 0; i < golden.size(); ++i) {
            if (actual[i] != golden[i]) {
                INFO("first difference at line " << i + 1 << "\n  golden: " << golden[i] << "\n  actual: " << actual[i]);
                REQUIRE(actual[i] == golden[i]);
            }
        }
    }
}
