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

// (No ';' in test names: catch_discover_tests splits a name there and neither half runs.)
TEST_CASE("unplugging the controller idles the puppet, plugging it back resumes at once", "[pipeline]") {
    const SimConfig config = default_config().sim;
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
    const SimConfig config = default_config().sim;
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

namespace {
// A configuration text in the layout logs had before the thread settings and
// the graph build keys were split from what the tick reads: [realtime] between
// [locomotion] and [motion_graph], the build keys first in [motion_graph].
std::string old_style_config_text(std::string text, int input_priority, int window_frames) {
    const std::string graph_table = "\n[motion_graph]\n";
    const size_t at = text.find(graph_table);
    REQUIRE(at != std::string::npos);
    text.insert(at + graph_table.size(),
                "analysis_rate_hz = 30\nwindow_frames = " + std::to_string(window_frames) +
                    "\nneighbourhood_frames = 4\nthreshold_percentile = 5.0\nthreshold_absolute = 0.0\n"
                    "bridge_percentile = 90.0\ncontact_height = 0.08\ncontact_speed = 0.6\n");
    text.insert(at, "\n[realtime]\ninput_priority = " + std::to_string(input_priority) +
                        "\nsimulation_priority = 0\nrender_priority = 0\ninput_cpu = -1\nsimulation_cpu = -1\n"
                        "render_cpu = -1\nlock_memory = 0\n");
    return text;
}

std::vector<std::uint8_t> log_with_change(const std::string& config_text, const std::string& change_text,
                                          const SimConfig& config, const std::vector<TickInput>& ticks) {
    InputLogHeader header;
    header.tick_rate_hz = static_cast<std::uint32_t>(config.tick_rate_hz);
    header.clip_data_hash = Simulation(config).clip_data_hash();
    header.config_text = config_text;
    std::vector<std::uint8_t> bytes = InputLogEncoder::encode_header(header);
    InputLogEncoder encoder;
    for (size_t k = 0; k < ticks.size(); ++k) {
        if (k == 300) encoder.append_config_change(change_text);
        encoder.append_tick(ticks[k]);
        if (encoder.pending_ticks() >= 60) encoder.finish_chunk(bytes);
    }
    encoder.append_end();
    encoder.finish_chunk(bytes);
    return bytes;
}
}  // namespace

TEST_CASE("a recorded log embeds only what the tick reads, older logs with realtime and build keys still replay",
          "[pipeline][config]") {
    const SimConfig config = default_config().sim;
    const StickProgram program = parse_stick_program("circle 3s radius=1 turns=1\n", "c.prog");
    PipelineOptions o = virtual_run(config, script_from_program(program, kSimulatedControllerHz), 3 * 240);
    o.record_file = temp_path("tick_keys.mlog");
    const PipelineResult r = run_pipeline(o);
    const DecodedInputLog recorded = decode_input_log(read_binary_file(o.record_file), o.record_file);
    std::remove(o.record_file.c_str());
    const std::string& text = recorded.header.config_text;
    CHECK(text == serialize_config(config));
    CHECK(text.find("[realtime]") == std::string::npos);
    for (const char* build_key : {"input_priority", "lock_memory", "analysis_rate_hz", "window_frames",
                                  "neighbourhood_frames", "threshold_percentile", "bridge_percentile", "contact_speed"}) {
        INFO(build_key);
        CHECK(text.find(build_key) == std::string::npos);
    }
    // The controller's path costs are the tick's: they stay.
    CHECK(text.find("transition_weight = ") != std::string::npos);
    CHECK(replay_log(recorded, "recorded", {}).final_hash == r.final_hash);

    // The same run as an older recorder wrote it: thread settings and build keys
    // in the header and in a change, which also retunes what the tick reads.
    SimConfig slow = config;
    slow.max_speed = 1.25f;
    const std::string old_text = old_style_config_text(text, 80, 12);
    const std::string old_change = old_style_config_text(serialize_config(slow), 90, 14);
    const AppConfig read_back = config_from_text(old_text, "old.mlog");
    CHECK(read_back.realtime.input_priority == 80);          // accepted as written ...
    CHECK(read_back.graph_build.graph_window_frames == 12);
    CHECK(serialize_config(read_back.sim) == text);          // ... and not part of the tick's configuration
    const DecodedInputLog old_log = decode_input_log(log_with_change(old_text, old_change, config, recorded.ticks), "old.mlog");
    const DecodedInputLog new_log =
        decode_input_log(log_with_change(text, serialize_config(slow), config, recorded.ticks), "new.mlog");
    ReplayOptions ro;
    ro.keep_tick_hashes = true;
    const ReplayResult old_run = replay_log(old_log, "old.mlog", ro);
    const ReplayResult new_run = replay_log(new_log, "new.mlog", ro);
    CHECK(old_run.config_changes == 1);
    CHECK(old_run.tick_hashes == new_run.tick_hashes);
    CHECK(old_run.final_hash != r.final_hash);  // the change took effect
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

TEST_CASE("the frame loop's three interpolations: one tick behind, carried ahead, the newest as it is", "[pipeline]") {
    struct Expected {
        Interpolation mode;
        float at_tick, quarter, late;         // root x at the current tick's time, a quarter tick on, 40 ticks on
        std::uint64_t shown_at_tick, shown_late;
    };
    // previous (tick 6) at x = 0, current (tick 7) at x = 1.
    const Expected cases[] = {{Interpolation::interpolate, 0.0f, 0.25f, 1.0f, 6, 7},
                              {Interpolation::extrapolate, 1.0f, 1.25f, 2.0f, 7, 7},
                              {Interpolation::latest, 1.0f, 1.0f, 1.0f, 7, 7}};
    for (const Expected& e : cases) {
        INFO("mode " << interpolation_name(e.mode));
        auto shared = std::make_unique<PipelineShared>();
        FrameLoop frames(*shared, e.mode);
        StateFrame& f = shared->states.back();
        f.previous.root_position = vec3(0.0f);
        f.previous.tick = 6;
        f.current.root_position = vec3(1.0f, 0.0f, 0.0f);
        f.current.tick = 7;
        f.current_time_ns = 1000;
        f.tick_ns = 100;
        shared->states.publish();
        CHECK(frames.run_frame(1000).x == e.at_tick);
        CHECK(frames.shown_tick() == e.shown_at_tick);
        CHECK(frames.run_frame(1025).x == e.quarter);
        CHECK(frames.run_frame(5000).x == e.late);  // never more than one tick ahead
        CHECK(frames.shown_tick() == e.shown_late);
        CHECK(frames.run_frame(0).x == e.at_tick);  // never before the pair
    }
}

namespace {
// Publishes the pair (tick − 1, tick) with the history entry of `tick`.
void publish_tick(PipelineShared& sh, TickStampHistory& history, std::uint64_t tick, std::uint32_t samples,
                  std::int64_t oldest, std::int64_t newest, std::int64_t ran) {
    history[tick % kTickStampHistory] = {tick, samples, oldest, newest, ran};
    StateFrame& f = sh.states.back();
    f.previous.tick = tick - 1;
    f.current.tick = tick;
    f.current_time_ns = static_cast<std::int64_t>(tick) * 1000;
    f.tick_ns = 1000;
    f.recent_inputs = history;
    sh.states.publish();
}
}  // namespace

TEST_CASE("a presented frame counts the oldest and newest sample of every tick it is the first to show",
          "[pipeline]") {
    auto shared = std::make_unique<PipelineShared>();
    TickStampHistory history{};
    FrameLoop frames(*shared, Interpolation::latest);
    // Ticks 1–4 between two frames (ms): tick 2 consumed nothing; tick 3 was overwritten before a frame read it.
    publish_tick(*shared, history, 1, 3, 100'000, 300'000, 1'000'000);
    frames.run_frame(1'000);
    frames.presented(2'000'000);  // shows tick 1: oldest 1.9 ms, newest 1.7 ms ago
    publish_tick(*shared, history, 2, 0, 0, 0, 2'000'000);
    publish_tick(*shared, history, 3, 2, 2'100'000, 2'500'000, 3'000'000);
    publish_tick(*shared, history, 4, 1, 3'600'000, 3'600'000, 4'000'000);
    frames.run_frame(4'000);
    frames.presented(6'000'000);  // shows ticks 2–4 for the first time: oldest 2.1 ms, newest 3.6 ms
    frames.run_frame(4'500);
    frames.presented(7'000'000);  // the same tick again: nothing new reached this frame
    const PresentLatency& p = frames.present_latency();
    REQUIRE(p.oldest.count == 2);
    CHECK(p.oldest.max_ns == 6'000'000 - 2'100'000);
    CHECK(p.oldest.sum_ns == (2'000'000 - 100'000) + (6'000'000 - 2'100'000));
    CHECK(p.newest.sum_ns == (2'000'000 - 300'000) + (6'000'000 - 3'600'000));
    CHECK(p.tick_to_present.sum_ns == (2'000'000 - 1'000'000) + (6'000'000 - 4'000'000));

    // Interpolating one tick behind, tick 5 reaches the screen only once the frame is a tick past it.
    FrameLoop behind(*shared, Interpolation::interpolate);
    publish_tick(*shared, history, 5, 1, 4'500'000, 4'500'000, 5'000'000);
    behind.run_frame(5'000);         // shows tick 4 (and, first for this loop, ticks 1–3)
    behind.presented(5'100'000);
    behind.run_frame(6'000);         // s = 1: tick 5 in full
    behind.presented(6'100'000);
    REQUIRE(behind.present_latency().newest.count == 2);
    CHECK(behind.present_latency().newest.max_ns == 6'100'000 - 4'500'000);
    CHECK(behind.present_latency().oldest.max_ns == 5'100'000 - 100'000);  // tick 1's oldest, still in the history
}

TEST_CASE("the interpolation choice changes what is drawn, never the ticks, hashes or recording", "[pipeline]") {
    const SimConfig config = default_config().sim;
    const StickProgram program = parse_stick_program("circle 2s radius=1 turns=1\npress south 50ms\nhold 500ms ly=-1\n",
                                                     "c.prog");
    std::vector<std::vector<std::uint8_t>> logs;
    std::vector<std::uint64_t> hashes;
    for (const Interpolation mode : {Interpolation::interpolate, Interpolation::extrapolate, Interpolation::latest}) {
        INFO("mode " << interpolation_name(mode));
        PipelineOptions o = virtual_run(config, script_from_program(program, kSimulatedControllerHz), 3 * 240);
        o.interpolation = mode;
        o.record_file = temp_path("interp_" + interpolation_name(mode) + ".mlog");
        const PipelineResult r = run_pipeline(o);
        CHECK(r.interpolation == mode);
        CHECK(r.ticks == 3 * 240);
        CHECK(r.frames > 0);
        logs.push_back(read_binary_file(o.record_file));
        hashes.push_back(r.final_hash);
        std::remove(o.record_file.c_str());
    }
    CHECK(logs[0] == logs[1]);
    CHECK(logs[0] == logs[2]);
    CHECK(hashes[0] == hashes[1]);
    CHECK(hashes[0] == hashes[2]);
}

TEST_CASE("a real-time run reports input to present per frame, ordered and after input to tick", "[pipeline]") {
    const SimConfig config = default_config().sim;
    const StickProgram program = parse_stick_program("circle 2s radius=1 turns=1\n", "c.prog");
    for (const Interpolation mode : {Interpolation::interpolate, Interpolation::latest}) {
        INFO("mode " << interpolation_name(mode));
        PipelineOptions o;
        o.config = config;
        o.script = script_from_program(program, kSimulatedControllerHz);
        o.total_ticks = 240 + 120;  // 1.5 s
        o.status_lines = false;
        o.interpolation = mode;
        const PipelineResult r = run_pipeline(o);
        const PresentLatency& p = r.present_latency;
        REQUIRE(p.oldest.count > 10);
        CHECK(p.newest.count == p.oldest.count);
        for (const PresentLatencyHistogram* h : {&p.oldest, &p.newest, &p.tick_to_present}) {
            CHECK(h->quantile_ns(0.5) <= h->quantile_ns(0.99));
            CHECK(h->quantile_ns(0.99) <= h->max_ns);
        }
        // Per frame the oldest sample waited at least as long as the newest.
        CHECK(p.newest.quantile_ns(0.5) <= p.oldest.quantile_ns(0.5));
        CHECK(p.newest.max_ns <= p.oldest.max_ns);
        // Each sample is presented after its tick ran, and a frame's oldest sample is its worst.
        CHECK(p.oldest.quantile_ns(0.5) >= r.input_latency.quantile_ns(0.5));
        CHECK(p.oldest.quantile_ns(0.99) >= r.input_latency.quantile_ns(0.5));
    }
}
