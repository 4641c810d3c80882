// The live pipeline with its real threads, in virtual time (deterministic):
// hot-plug, live replay of a log with configuration changes, and run ≡ replay.
#include <catch2/catch.hpp>

#include <cstdio>
#include <filesystem>

#include "app/config/config.hpp"
#include "app/io/files.hpp"
#include "app/live/pipeline.hpp"
#include "app/eval/replay.hpp"

using namespace marionette;

namespace {
std::string temp_path(const std::string& name) {
    return (std::filesystem::temp_directory_path() / ("marionette_pipeline_" + name)).string();
}

std::string read_stream(std::FILE* f) {
    std::rewind(f);
    std::string out;
    char buf[4096];
    size_t n = 0;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) out.append(buf, n);
    return out;
}

PipelineOptions virtual_run(const SimConfig& config, InputScript script, std::uint64_t ticks) {
    PipelineOptions o;
    o.config = config;
    o.script = std::move(script);
    o.total_ticks = ticks;
    o.virtual_time = true;
    o.status_lines = false;
    return o;
}
}  // namespace

TEST_CASE("unplugging the controller idles the puppet; plugging it back resumes at once", "[pipeline]") {
    const SimConfig config = default_config();
    const StickProgram program = parse_stick_program("hold 6s ly=1 lx=0.25\n", "forward.prog");
    InputScript script = script_from_program(program, kSimulatedControllerHz, {{2.0, 1.5}});
    PipelineOptions o = virtual_run(config, std::move(script), 6 * 240);
    o.record_file = temp_path("unplug.mlog");
    std::FILE* out = std::tmpfile();
    REQUIRE(out);
    o.out = out;
    const PipelineResult r = run_pipeline(o);
    const std::string printed = read_stream(out);
    std::fclose(out);

    CHECK(r.ticks == 6 * 240);
    CHECK(r.disconnects == 1);
    CHECK(r.reconnects == 1);
    CHECK_THAT(printed, Catch::Contains("controller disconnected: the puppet idles"));
    CHECK_THAT(printed, Catch::Contains("controller connected: resuming"));

    const DecodedInputLog log = decode_input_log(read_binary_file(o.record_file), o.record_file);
    REQUIRE(log.ticks.size() == 6 * 240);
    // Tick k runs at (k+1)·dt and consumes samples stamped up to then.
    const std::int64_t dt = 1'000'000'000 / 240;
    auto first_tick_at = [&](double seconds) {
        const auto t = static_cast<std::int64_t>(seconds * 1e9);
        return static_cast<size_t>((t + dt - 1) / dt - 1);
    };
    const size_t gone = first_tick_at(2.0), back = first_tick_at(3.5);
    CHECK(log.ticks[gone - 1].left_y == 32767);  // driving before the unplug
    for (size_t k = gone; k < back; ++k) {
        INFO("tick " << k);
        REQUIRE(log.ticks[k] == TickInput{});     // idle for the whole time it is away
    }
    // Back within a second of the reconnect (here: on the very tick that sees it).
    CHECK(log.ticks[back].left_y == 32767);
    CHECK(log.ticks[back].left_x == quantize_stick(0.25));
    // And the puppet stood still while it was away, then walked on.
    ReplayOptions ro;
    ro.keep_tick_hashes = true;
    const ReplayResult replayed = replay_log(log, o.record_file, ro);
    CHECK(replayed.final_hash == r.final_hash);
    std::remove(o.record_file.c_str());
}

TEST_CASE("a log with configuration changes replayed live gives the replay's states", "[pipeline]") {
    const SimConfig config = default_config();
    SimConfig slow = config;
    slow.max_speed = 1.25f;
    slow.turn_rate_deg_s = 90.0f;
    // Build a log by hand: a circle program's ticks with a change before tick 300.
    const StickProgram program = parse_stick_program("circle 4s radius=1 turns=1\n", "c.prog");
    const std::vector<TickInput> ticks = render_stick_program(program, config.tick_rate_hz);
    InputLogHeader header;
    header.tick_rate_hz = 240;
    header.clip_data_hash = Simulation(config).clip_data_hash();
    header.config_text = serialize_config(config);
    std::vector<std::uint8_t> bytes = InputLogEncoder::encode_header(header);
    InputLogEncoder encoder;
    for (size_t k = 0; k < ticks.size(); ++k) {
        if (k == 300) encoder.append_config_change(serialize_config(slow));
        encoder.append_tick(ticks[k]);
        if (encoder.pending_ticks() >= 60) encoder.finish_chunk(bytes);
    }
    encoder.append_end();
    encoder.finish_chunk(bytes);
    const DecodedInputLog log = decode_input_log(bytes, "made.mlog");
    REQUIRE(log.config_changes.size() == 1);

    ReplayOptions ro;
    ro.trace_csv = temp_path("replay.csv");
    const ReplayResult replayed = replay_log(log, "made.mlog", ro);

    PipelineOptions o = virtual_run(config, script_from_log(log, 1'000'000'000 / 240), log.ticks.size());
    o.scheduled_changes.push_back({300, slow});
    o.trace_file = temp_path("live.csv");
    o.record_file = temp_path("live.mlog");
    std::FILE* out = std::tmpfile();
    o.out = out;
    const PipelineResult r = run_pipeline(o);
    std::fclose(out);
    CHECK(r.final_hash == replayed.final_hash);
    CHECK(r.config_changes == 1);
    CHECK(read_text_file(o.trace_file) == read_text_file(ro.trace_csv));
    // The live run's own recording holds the change at the same tick.
    const DecodedInputLog again = decode_input_log(read_binary_file(o.record_file), o.record_file);
    REQUIRE(again.config_changes.size() == 1);
    CHECK(again.config_changes[0].before_tick == 300);
    CHECK(again.ticks == log.ticks);
    for (const std::string& f : {ro.trace_csv, o.trace_file, o.record_file}) std::remove(f.c_str());
}

TEST_CASE("the frame loop interpolates one tick behind and never past the newest state", "[pipeline]") {
    auto shared = std::make_unique<PipelineShared>();
    FrameLoop frames(*shared);
    CHECK(frames.run_frame(0) == vec3(0.0f));
    CHECK_FALSE(frames.has_state());
    StateFrame& f = shared->states.back();
    f.previous.root_position = vec3(0.0f, 0.0f, 0.0f);
    f.current.root_position = vec3(1.0f, 0.0f, 0.0f);
    f.current_time_ns = 1000;
    f.tick_ns = 100;
    shared->states.publish();
    CHECK(frames.run_frame(1000).x == 0.0f);     // at the current tick's time: the previous state
    CHECK(frames.run_frame(1025).x == 0.25f);
    CHECK(frames.alpha() == Approx(0.25));
    CHECK(frames.run_frame(1100).x == 1.0f);
    CHECK(frames.run_frame(5000).x == 1.0f);     // late frames hold the newest state
    CHECK(frames.run_frame(0).x == 0.0f);        // and early ones the previous, never extrapolating
}
