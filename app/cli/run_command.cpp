// `marionette run`: the live program. It chooses the input and display, prepares
// the pipeline (app/live/pipeline.hpp: input, simulation, render and writer threads),
// turns SIGINT/SIGTERM into a clean stop, and reports the run's statistics.
#include <fmt/format.h>

#include <atomic>
#include <csignal>
#include <cstdlib>
#include <limits>
#include <memory>

#include "app/cli/cli.hpp"
#include "app/io/log.hpp"
#include "app/live/clock.hpp"
#include "app/cli/commands.hpp"
#include "app/config/config.hpp"
#include "app/config/config_search.hpp"
#include "app/io/files.hpp"
#include "app/graph/graph_files.hpp"
#include "app/graph/graph_rebuild.hpp"
#include "app/io/json.hpp"
#include "app/live/pipeline.hpp"
#include "app/live/recording.hpp"
#include "app/config/program_source.hpp"
#include "app/config/embedded.hpp"
#include "app/config/character_config.hpp"
#include "runtime/gait/puppet.hpp"
#include "app/config/render_config.hpp"
#include "input/evdev/evdev_backend.hpp"
#include "input/hid/hidapi_transport.hpp"
#include "input/input_thread.hpp"
#include "input/sdl/sdl_backend.hpp"
#include "app/eval/replay.hpp"

namespace marionette {

namespace {
std::atomic<bool> g_stop_requested{false};
std::atomic<std::int64_t> g_stop_requested_ns{0};
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<std::int64_t>::is_always_lock_free,
              "the signal handler may only touch lock-free atomics");

extern "C" void on_stop_signal(int) {
    // clock_gettime is async-signal-safe; the time measures how fast we shut down.
    if (!g_stop_requested.load()) g_stop_requested_ns.store(monotonic_ns());
    g_stop_requested.store(true);
}

std::string histogram_json(std::int64_t p50, std::int64_t p99, std::int64_t max, std::int64_t mean) {
    return fmt::format("{{\"p50\":{},\"p99\":{},\"max\":{},\"mean\":{}}}", json::number(p50 / 1e3),
                       json::number(p99 / 1e3), json::number(max / 1e3), json::number(mean / 1e3));
}
template <typename Histogram>
std::string histogram_json(const Histogram& h) {
    return histogram_json(h.quantile_ns(0.5), h.quantile_ns(0.99), h.max_ns, h.mean_ns());
}
// The same in milliseconds.
std::string histogram_json_ms(const PresentLatencyHistogram& h) {
    return fmt::format("{{\"p50\":{},\"p99\":{},\"max\":{},\"mean\":{}}}", json::number(h.quantile_ns(0.5) / 1e6),
                       json::number(h.quantile_ns(0.99) / 1e6), json::number(h.max_ns / 1e6),
                       json::number(h.mean_ns() / 1e6));
}
// End to end, per frame that showed new input (docs/pipeline.md, "Latency").
std::string present_latency_json(const PipelineResult& r) {
    return fmt::format("\"interpolation\":{},\"input_to_present_ms\":{{\"frames\":{},\"oldest\":{},\"newest\":{}}},"
                       "\"tick_to_present_ms\":{}",
                       json::quote(interpolation_name(r.interpolation)), r.present_latency.oldest.count,
                       histogram_json_ms(r.present_latency.oldest), histogram_json_ms(r.present_latency.newest),
                       histogram_json_ms(r.present_latency.tick_to_present));
}

void write_stats_json(const std::string& path, const RunOptions& o, const SimConfig& config, const PipelineResult& r) {
    const std::string text = fmt::format(
        "{{\"input\":{},\"display\":{},\"tick_rate_hz\":{},\"ticks\":{},\"duration_s\":{},\"wall_s\":{},"
        "\"stopped\":{},\"shutdown_ms\":{},\"final_hash\":\"{:016x}\","
        "\"tick_time_us\":{},\"frame_time_us\":{},\"input_to_tick_latency_us\":{},{},"
        "\"samples\":{},\"dropped_samples\":{},\"frames\":{},\"missed_frames\":{},\"catch_up_drops\":{},"
        "\"catch_up_skipped_s\":{},\"max_ticks_per_wake\":{},"
        "\"records_dropped\":{},\"config_changes\":{},\"disconnects\":{},\"reconnects\":{},"
        "\"distance_m\":{},\"top_speed_m_s\":{},\"realtime_warning\":{}}}\n",
        json::quote(o.input), json::quote(r.display_description.empty() ? "headless" : r.display_description),
        config.tick_rate_hz, r.ticks, json::number(static_cast<double>(r.ticks) / config.tick_rate_hz),
        json::number(r.wall_s), r.stopped ? "true" : "false", json::number(r.shutdown_ms), r.final_hash,
        histogram_json(r.tick_time), histogram_json(r.frame_time), histogram_json(r.input_latency),
        present_latency_json(r), r.samples_pushed,
        r.samples_dropped, r.frames, r.missed_frames, r.catch_up_drops, json::number(r.catch_up_skipped_s),
        r.max_ticks_per_wake, r.records_dropped, r.config_changes,
        r.disconnects, r.reconnects, json::number(r.distance_m), json::number(r.top_speed),
        r.realtime_warning.empty() ? "null" : json::quote(r.realtime_warning));
    write_text_file(path, text);
}

// Virtual time waits for the input thread's watermark, which only a script
// provides: a pad's samples arrive in real time, so --fast would never tick.
[[noreturn]] void throw_fast_needs_script() {
    throw ImportError("--fast", 0,
                      "needs a simulated or recorded input (sim:PROGRAM or log:FILE): a real controller runs in real "
                      "time");
}

// Ok when the backend named on the command line has a pad to read, else why not.
// Checked before the run starts so the error is immediate and exits 2.
Outcome find_pad(const std::string& backend, const std::string& evdev_dir) {
    if (backend == "evdev") {
        if (input::enumerate_evdev_gamepads(evdev_dir).empty())
            return Outcome::failure("no gamepad under " + evdev_dir + " (is it plugged in and readable? see `marionette input list`)");
    } else if (backend == "hidraw") {
        if (input::enumerate_hid_pads().empty())
            return Outcome::failure("no supported HID pad found (see `marionette input list`)");
    } else if (backend == "sdl") {
        input::SdlBackend sdl;
        if (const Outcome started = sdl.start(""); !started.ok()) return Outcome::failure("SDL2 cannot start: " + started.problem());
        if (sdl.joysticks() == 0) return Outcome::failure("SDL2 sees no joystick");
    }
    return Outcome::success();
}

// What --input resolved to: "auto" probes for a controller (input/auto_select.hpp)
// and falls back to the simulated controller playing the demo.
struct InputChoice {
    std::string input;
    bool use_device = false;
};

InputChoice choose_input(const RunOptions& o, input::InputThreadOptions& device) {
    InputChoice c{o.input, false};
    if (c.input == "auto") {
        const input::BackendChoice choice = input::probe_input_backend(device.evdev_dir);
        if (choice.kind == input::BackendKind::none) {
            fmt::print("marionette: no controller found ({}); the simulated controller plays the demo\n", choice.reason);
            c.input = "sim:builtin:demo";
        } else {
            device.backend = "auto";
            c.use_device = true;
        }
    } else if (c.input == "evdev" || c.input == "hidapi" || c.input == "sdl") {
        device.backend = c.input == "hidapi" ? "hidraw" : c.input;
        c.use_device = true;
        if (o.fast) throw_fast_needs_script();
        // Asked for by name: no pad is an error now, not a run that idles forever.
        if (const Outcome found = find_pad(device.backend, device.evdev_dir); !found.ok())
            throw ImportError("--input " + c.input, 0, found.problem());
    }
    if (c.use_device && o.fast) throw_fast_needs_script();
    if (!o.unplug.empty() && c.input.rfind("sim:", 0) != 0)
        throw ImportError("--sim-unplug", 0, "only the simulated controller (--input sim:PROGRAM) can be unplugged");
    return c;
}

// `--input sim:PROGRAM`: the program played by a simulated controller, unplugged
// where --sim-unplug says. Returns the description for the banner.
std::string prepare_program_input(const RunOptions& o, const std::string& program_name, const SimConfig& config,
                                  PipelineOptions& p) {
    const StickProgram program = load_program(program_name);
    std::vector<UnplugWindow> unplug;
    for (size_t i = 0; i + 1 < o.unplug.size(); i += 2) unplug.push_back({o.unplug[i], o.unplug[i + 1]});
    p.script = script_from_program(program, kSimulatedControllerHz, unplug);
    p.total_ticks = static_cast<std::uint64_t>(std::llround(program.duration_s() * config.tick_rate_hz));
    return fmt::format("simulated controller playing '{}' ({:.1f} s) at {} Hz", program.name, program.duration_s(),
                       kSimulatedControllerHz);
}

// `--input log:FILE`: the recording's own configuration, so the live replay
// matches it (--config may retune on top, nothing structural), and its recorded
// changes scheduled before their ticks. Returns the description for the banner.
std::string prepare_log_input(const RunOptions& o, const std::string& file, AppConfig& config, PipelineOptions& p) {
    const DecodedInputLog log = decode_input_log(read_input_log_bytes(file), file);
    if (!log.warning.empty()) log_message(LogLevel::warning, fmt::format("warning: {}", log.warning));
    config = config_from_text(log.header.config_text, file + " (embedded configuration)");
    if (!o.config_file.empty()) {
        const AppConfig tuned = apply_config_text(config, read_text_file(o.config_file), o.config_file);
        if (const Outcome kept = structure_unchanged(config.sim, tuned.sim); !kept.ok())
            throw ConfigError(o.config_file, 0, kept.problem(), "differs from the log's and cannot change for a live replay");
        config = tuned;
    }
    SimConfig running = config.sim;
    for (const InputLogConfigChange& change : log.config_changes) {
        const SimConfig next = apply_config_change(running, change.config_text,
                                                   fmt::format("{} (config change before tick {})", file, change.before_tick));
        if (const Outcome kept = structure_unchanged(running, next); !kept.ok())
            throw ImportError(file, 0, "recorded configuration change alters " + kept.problem() + ", which cannot change live");
        p.scheduled_changes.push_back({change.before_tick, next});
        running = next;
    }
    p.script = script_from_log(log, 1'000'000'000 / config.sim.tick_rate_hz);
    p.total_ticks = log.ticks.size();
    return fmt::format("input log {} ({} ticks)", file, log.ticks.size());
}

// The display: a window or KMS draws with render_es (the run then lasts until
// the window is closed); headless (also what auto picks with no display) runs
// the interpolating frame loop without a GPU.
render::PlatformKind prepare_display(const RunOptions& o, const ConfigSearchDirs& config_dirs,
                                     render::PlatformRequest request, PipelineOptions& p) {
    const render::PlatformKind kind = render::select_platform(request, render::detect_display_environment());
    if (kind == render::PlatformKind::headless) return kind;
    const ConfigLookup render_found = find_config_file(o.render_config_file, "render.toml", config_dirs);
    const RenderConfig rc = load_render_config(render_found.file);
    fmt::print("marionette: render settings: {}\n", describe_config_lookup(render_found));
    p.display.gl = true;
    p.display.settings = rc.settings;
    p.display.body = load_render_character(rc, make_puppet_skeleton(p.config));
    p.display.platform.kind = kind;
    p.display.platform.width = rc.settings.width;
    p.display.platform.height = rc.settings.height;
    p.display.platform.msaa_samples = rc.settings.msaa_samples;
    p.display.platform.vsync = rc.settings.vsync;
    p.display.platform.fullscreen = rc.settings.fullscreen;
    p.display.platform.drm_device = rc.drm_device;
    p.display.platform.kms_mode = rc.kms;
    // With a display the run lasts until the window is closed (or --duration).
    p.total_ticks = std::numeric_limits<std::uint64_t>::max();
    return kind;
}

render::PlatformRequest display_request(const std::string& display) {
    if (display == "window") return render::PlatformRequest::window;
    if (display == "kms") return render::PlatformRequest::kms;
    if (display == "headless") return render::PlatformRequest::headless;
    return render::PlatformRequest::automatic;
}

void print_run_banner(const RunOptions& o, const PipelineOptions& p, render::PlatformKind kind, const std::string& source) {
    const int rate = p.config.tick_rate_hz;
    if (p.total_ticks == std::numeric_limits<std::uint64_t>::max())
        fmt::print("marionette: {} run, {} at {} Hz until {}{}\n", render::platform_name(kind), source, rate,
                   p.display.gl ? "the window is closed" : "stopped (Ctrl-C)", o.fast ? " (no real-time pacing)" : "");
    else
        fmt::print("marionette: {} run, {} at {} Hz for {:.1f} s{}\n", render::platform_name(kind), source, rate,
                   static_cast<double>(p.total_ticks) / rate, o.fast ? " (no real-time pacing)" : "");
    if (!o.config_file.empty()) fmt::print("marionette: watching {} for live tuning\n", o.config_file);
    std::fflush(stdout);
}

// Runs the pipeline with SIGINT/SIGTERM turned into a clean stop. When auto
// found a display it could not open, says so and runs headless instead.
PipelineResult run_stoppable(const RunOptions& o, PipelineOptions& p, render::PlatformRequest request,
                             std::uint64_t headless_ticks) {
    g_stop_requested.store(false);
    g_stop_requested_ns.store(0);
    std::signal(SIGINT, on_stop_signal);
    std::signal(SIGTERM, on_stop_signal);
    PipelineResult r;
    try {
        r = run_pipeline(p);
    } catch (const render::PlatformError& e) {
        if (request != render::PlatformRequest::automatic) throw;
        log_message(LogLevel::warning, fmt::format("warning: {}; running headless", e.what()));
        p.display.gl = false;
        if (o.duration_s < 0.0) p.total_ticks = headless_ticks;
        r = run_pipeline(p);
    }
    if (!r.display_description.empty()) fmt::print("display: {}\n", r.display_description);
    if (!r.input_description.empty()) fmt::print("input: {}\n", r.input_description);
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    return r;
}

// The closing summary; 1 when the writer fell behind and outputs are incomplete.
int report_run(const RunOptions& o, const SimConfig& config, const PipelineResult& r) {
    if (!o.stats_json.empty()) write_stats_json(o.stats_json, o, config, r);
    fmt::print("{}: {:.1f} s, {} ticks; walked {:.1f} m, top speed {:.2f} m/s; {} catch-up drops; "
               "input→tick latency p50 {:.2f} ms p99 {:.2f} ms max {:.2f} ms; input→present ({}) p50 {:.2f} ms "
               "p99 {:.2f} ms max {:.2f} ms; {} samples dropped; {} frames ({} missed); "
               "final state hash {:016x}\n",
               r.stopped ? "stopped" : (r.display_closed ? "window closed" : "demo finished"), static_cast<double>(r.ticks) / config.tick_rate_hz, r.ticks,
               r.distance_m, r.top_speed, r.catch_up_drops, r.input_latency.quantile_ns(0.5) / 1e6,
               r.input_latency.quantile_ns(0.99) / 1e6, r.input_latency.max_ns / 1e6,
               interpolation_name(r.interpolation), r.present_latency.oldest.quantile_ns(0.5) / 1e6,
               r.present_latency.oldest.quantile_ns(0.99) / 1e6, r.present_latency.oldest.max_ns / 1e6,
               r.samples_dropped, r.frames,
               r.missed_frames, r.final_hash);
    if (!r.record_files.empty())
        fmt::print("recording: {}{}{}\n", r.record_files.front(),
                   r.record_files.size() > 1 ? fmt::format(" and {} continuation files", r.record_files.size() - 1) : "",
                   r.recording_stopped.empty() ? "" : " (ended early: " + r.recording_stopped + ")");
    if (r.watchdog_pings + r.watchdog_withheld > 0)
        fmt::print("watchdog: {} pings sent, {} withheld (a loop made no progress)\n", r.watchdog_pings, r.watchdog_withheld);
    if (r.stopped) fmt::print("shutdown: threads joined and files closed {:.1f} ms after the signal\n", r.shutdown_ms);
    if (r.records_dropped > 0) {
        log_message(LogLevel::error, fmt::format("error: the writer fell behind and {} tick records were lost: {}{}are incomplete",
                   r.records_dropped, o.record_file.empty() ? "" : o.record_file + " ",
                   o.trace_file.empty() ? "" : o.trace_file + " "));
        return 1;
    }
    return 0;
}

// --record FILE, or --record auto: a new file in the recordings directory
// (docs/deploy.md), whose oldest recordings make room under [recording]'s limits.
void prepare_recording(const RunOptions& o, const AppConfig& config, PipelineOptions& p) {
    if (o.record_file.empty()) return;
    p.record_limits = recording_limits(config.recording);
    if (o.record_file == "auto") {
        p.record_rotate_dir = default_recordings_dir();
        p.record_file = new_recording_path(p.record_rotate_dir);
    } else {
        p.record_file = o.record_file;
        p.record_limits.max_total_bytes = 0;  // not our directory: nothing is deleted there
    }
    fmt::print("marionette: recording to {}\n", p.record_file);
}

// MARIONETTE_TEST_STALL_SIM_MS (the watchdog test's hook): milliseconds, 0–600000.
std::int64_t test_stall_from_environment() {
    const char* v = std::getenv("MARIONETTE_TEST_STALL_SIM_MS");
    if (v == nullptr || *v == '\0') return 0;
    char* end = nullptr;
    const long long ms = std::strtoll(v, &end, 10);
    if (*end != '\0' || ms < 0 || ms > 600000)
        throw ImportError("MARIONETTE_TEST_STALL_SIM_MS", 0, std::string("'") + v + "' is not a number of milliseconds in [0, 600000]");
    return ms;
}

}  // namespace

int run_command(const RunOptions& o) {
    // --config, else ~/.config/marionette/, else /etc/marionette/, else the defaults (docs/deploy.md).
    const ConfigSearchDirs config_dirs = config_search_dirs_from_environment();
    const ConfigLookup config_found = find_config_file(o.config_file, "marionette.toml", config_dirs);
    AppConfig config = load_config(config_found.file);
    fmt::print("marionette: configuration: {}\n", describe_config_lookup(config_found));
    PipelineOptions p;
    input::InputThreadOptions device;
    const InputChoice input = choose_input(o, device);
    std::string source;
    if (input.use_device) {
        device.config = input::apply_input_config_text(input::InputConfig{}, embedded::find("config/input.toml"),
                                                       "config/input.toml");
        p.device = &device;
        p.total_ticks = std::numeric_limits<std::uint64_t>::max();  // until stopped
        source = "controller (" + device.backend + ")";
    } else if (input.input.rfind("sim:", 0) == 0) {
        source = prepare_program_input(o, input.input.substr(4), config.sim, p);
    } else if (input.input.rfind("log:", 0) == 0) {
        source = prepare_log_input(o, input.input.substr(4), config, p);
    } else {
        throw ImportError("--input " + input.input, 0, "expected auto, evdev, hidapi, sdl, sim:PROGRAM or log:FILE");
    }
    const std::uint64_t headless_ticks = p.total_ticks;
    const render::PlatformRequest request = display_request(o.display);
    const render::PlatformKind kind = prepare_display(o, config_dirs, request, p);
    if (o.duration_s >= 0.0) p.total_ticks = static_cast<std::uint64_t>(o.duration_s * config.sim.tick_rate_hz + 0.5);

    p.config = config.sim;
    p.realtime = config.realtime;
    p.interpolation = config.timing.interpolation;
    p.graph = load_graph_argument_rebuilding_stale(o.graph_file, config.sim, config.graph_build);
    p.graph_argument = o.graph_file;
    p.virtual_time = o.fast;
    prepare_recording(o, config, p);
    p.test_stall_simulation_ms = test_stall_from_environment();
    p.trace_file = o.trace_file;
    p.watch_config_file = o.config_file;  // live tuning of the file given
    p.ui = config.ui.enabled;              // the tuning UI over a window or KMS (docs/ui.md)
    p.ui_base = config;
    p.ui_config_file = config_found.file;
    p.stop_request = &g_stop_requested;
    p.stop_request_time_ns = &g_stop_requested_ns;

    print_run_banner(o, p, kind, source);
    const PipelineResult r = run_stoppable(o, p, request, headless_ticks);
    return report_run(o, config.sim, r);
}

void register_run_command(CLI::App& app, int& exit_code) {
    auto o = std::make_shared<RunOptions>();
    CLI::App* cmd = app.add_subcommand("run", "Run the puppet live (headless demo with a simulated controller by default)");
    cmd->add_option("--config", o->config_file, "TOML file overriding the defaults; watched for live tuning")
        ->check(CLI::ExistingFile);
    cmd->add_option("--input", o->input, "auto|evdev|hidapi|sdl|sim:PROGRAM|log:FILE (PROGRAM: a file or builtin:NAME)");
    cmd->add_option("--display", o->display, "auto|kms|window|headless")
        ->check(CLI::IsMember({"auto", "headless", "kms", "window"}));
    cmd->add_option("--record", o->record_file,
                    "write the input log to FILE, or auto: a new file in the recordings directory ([recording])");
    cmd->add_option("--trace", o->trace_file, "per-tick CSV: tick,hash,root_x,root_y,root_z (as replay --trace)");
    cmd->add_option("--graph", o->graph_file, "drive the puppet from this motion graph (.mgraph, or default: the embedded one)");
    cmd->add_option("--stats-json", o->stats_json, "write the run's statistics here as JSON");
    cmd->add_option("--duration", o->duration_s, "seconds to run (default: until the input ends)")
        ->check(CLI::Range(0.0, 86400.0));
    cmd->add_option("--sim-unplug", o->unplug, "AT FOR: unplug the simulated controller at AT s for FOR s (repeatable)")
        ->expected(2)
        ->take_all()
        ->check(CLI::Range(0.0, 86400.0));
    cmd->add_flag("--fast", o->fast, "no real-time pacing: virtual time, as fast as the CPU allows (deterministic)");
    on_parsed(cmd, exit_code, [o] { return run_command(*o); });
}

}  // namespace marionette
