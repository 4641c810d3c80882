// Golden per-tick traces for the shipped programs: the committed files in
// tests/golden/ were written by `marionette replay LOG --trace` (see
// docs/input-log.md, "Golden traces", to regenerate after an intended change).
// CI runs this in the optimised and the asan build, so both must produce the
// same bits as the committed run.
#include <catch2/catch.hpp>

#include <sstream>

#include "app/config.hpp"
#include "app/program_source.hpp"
#include "app/replay.hpp"
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
    const SimConfig config = default_config();
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
    const DecodedInputLog log = decode_input_log(record("builtin:circle", default_config()), "circle");
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
    SimConfig slow = default_config();
    slow.max_speed = 1.0f;
    const DecodedInputLog log = decode_input_log(record("builtin:walk_stop", slow), "slow");
    const ReplayResult slow_run = replay_log(log, "slow", {});
    const DecodedInputLog normal = decode_input_log(record("builtin:walk_stop", default_config()), "normal");
    const ReplayResult normal_run = replay_log(normal, "normal", {});
    CHECK(slow_run.distance_m < normal_run.distance_m);
    CHECK(slow_run.final_hash != normal_run.final_hash);
}

TEST_CASE("a log whose clip data differ from this build is refused", "[golden]") {
    std::vector<std::uint8_t> bytes = record("builtin:stand_still", default_config());
    DecodedInputLog log = decode_input_log(bytes, "x");
    log.header.clip_data_hash ^= 1;
    CHECK_THROWS_WITH(replay_log(log, "x.mlog", {}), Catch::Contains("different clip data"));
}
