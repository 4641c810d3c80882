// Desync detection: a log's state-hash checkpoints are verified on replay, the
// first mismatch names its tick and both builds, and --no-verify replays on.
#include <catch2/catch.hpp>

#include "app/config/config.hpp"
#include "app/config/program_source.hpp"
#include "app/eval/log_provenance.hpp"
#include "app/eval/replay.hpp"

using namespace marionette;

namespace {
// Records like `marionette record`: a checkpoint every kCheckpointIntervalTicks and at the end.
DecodedInputLog record_with_checkpoints(const std::string& program_spec) {
    const SimConfig config = default_config().sim;
    const std::vector<TickInput> ticks = render_stick_program(load_program(program_spec), config.tick_rate_hz);
    Simulation sim(config);
    InputLogHeader header;
    header.tick_rate_hz = static_cast<std::uint32_t>(config.tick_rate_hz);
    header.clip_data_hash = sim.clip_data_hash();
    header.config_text = serialize_config(config);
    header.provenance = "marionette test recorder; some other build";
    std::vector<std::uint8_t> bytes = InputLogEncoder::encode_header(header);
    InputLogEncoder encoder;
    for (std::size_t k = 0; k < ticks.size(); ++k) {
        sim.step(ticks[k]);
        encoder.append_tick(ticks[k]);
        if ((k + 1) % kCheckpointIntervalTicks == 0 || k + 1 == ticks.size()) encoder.append_checkpoint(hash_state(sim.state()));
        if (encoder.pending_ticks() >= 60) encoder.finish_chunk(bytes);
    }
    encoder.append_end();
    encoder.finish_chunk(bytes);
    return decode_input_log(bytes, program_spec);
}
}  // namespace

TEST_CASE("replay verifies every checkpoint of an exact recording", "[checkpoint]") {
    const DecodedInputLog log = record_with_checkpoints("builtin:circle");
    REQUIRE(log.warning.empty());
    REQUIRE(log.checkpoints.size() >= 5);
    const ReplayResult r = replay_log(log, "circle.mlog", {});
    CHECK(r.checkpoints_verified == static_cast<int>(log.checkpoints.size()));
    CHECK(log.checkpoints.back().after_ticks == log.ticks.size());
}

TEST_CASE("an altered checkpoint stops the replay at its tick, naming both builds", "[checkpoint]") {
    DecodedInputLog log = record_with_checkpoints("builtin:walk_stop");
    REQUIRE(log.checkpoints.size() >= 3);
    log.checkpoints[2].state_hash ^= 1;
    const std::uint64_t tick = log.checkpoints[2].after_ticks;
    try {
        replay_log(log, "walk.mlog", {});
        FAIL("the altered checkpoint was not noticed");
    } catch (const ReplayDesync& e) {
        CHECK(e.tick() == tick);
        const std::string what = e.what();
        CHECK_THAT(what, Catch::Contains("at tick " + std::to_string(tick)));
        CHECK_THAT(what, Catch::Contains("marionette test recorder; some other build"));
        CHECK_THAT(what, Catch::Contains(build_provenance()));
    }
    ReplayOptions options;
    options.verify_checkpoints = false;
    const ReplayResult r = replay_log(log, "walk.mlog", options);
    CHECK(r.ticks == log.ticks.size());
    CHECK(r.checkpoints_verified == 0);
}

TEST_CASE("this build's provenance names version, compiler and architecture", "[checkpoint]") {
    const std::string p = build_provenance();
    CHECK_THAT(p, Catch::StartsWith("marionette "));
    CHECK((p.find("GCC") != std::string::npos || p.find("Clang") != std::string::npos));
    CHECK((p.find("x86_64") != std::string::npos || p.find("aarch64") != std::string::npos));
}
