// `marionette run`: the live program. Until the pipeline and renderer issues land
// it is a single thread: a simulated controller (stick program) feeds the
// fixed-step simulation in real time, headless, with a status line each second.
#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <memory>
#include <thread>

#include "app/cli.hpp"
#include "app/commands.hpp"
#include "app/config.hpp"
#include "app/files.hpp"
#include "app/live_view.hpp"
#include "app/program_source.hpp"
#include "app/replay.hpp"
#include "runtime/fixed_step.hpp"

namespace marionette {

namespace {
std::atomic<bool> g_stop_requested{false};
extern "C" void on_stop_signal(int) { g_stop_requested.store(true); }

const char* activity(float speed) {
    if (speed < 0.05f) return "standing";
    if (speed < 2.0f) return "walking";
    return "running";
}

std::string status_line(const PuppetState& s, double seconds, double distance) {
    const float speed = std::sqrt(s.velocity.x * s.velocity.x + s.velocity.y * s.velocity.y);
    return fmt::format("[{:6.1f} s] {:<8} {:4.2f} m/s  heading {:4.0f}°  at ({:6.2f}, {:6.2f})  walked {:5.1f} m",
                       seconds, activity(speed), speed, s.heading * det::kRadToDeg, s.root_position.x,
                       s.root_position.z, distance);
}
}  // namespace

int run_command(const RunOptions& o) {
    const SimConfig config = load_config(o.config_file);
    if (o.input.rfind("sim:", 0) != 0)
        throw ImportError(o.input, 0, "only the simulated controller (--input sim:PROGRAM) is available in this build");
    const StickProgram program = load_program(o.input.substr(4));
    std::vector<TickInput> ticks = render_stick_program(program, config.tick_rate_hz);
    std::uint64_t total_ticks = ticks.size();
    if (o.duration_s >= 0.0) total_ticks = static_cast<std::uint64_t>(o.duration_s * config.tick_rate_hz + 0.5);

    fmt::print("marionette: run, simulated controller playing '{}' ({:.1f} s) at {} Hz\n", program.name,
               static_cast<double>(total_ticks) / config.tick_rate_hz, config.tick_rate_hz);
    std::fflush(stdout);

    set_simulation_float_mode();
    Simulation sim(config);
    // A window or KMS display when --display (or auto) picks one; nullptr: console only.
    std::unique_ptr<LiveView> live = LiveView::open(o.display, o.render_config_file, sim);
    if (live) fmt::print("display: {}\n", live->description());
    PuppetState previous = sim.state();
    std::unique_ptr<InputLogFile> log;
    if (!o.record_file.empty()) {
        InputLogHeader header;
        header.tick_rate_hz = static_cast<std::uint32_t>(config.tick_rate_hz);
        header.clip_data_hash = sim.clip_data_hash();
        header.config_text = serialize_config(config);
        log = std::make_unique<InputLogFile>(o.record_file, header);
    }
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> trace(nullptr, &std::fclose);
    if (!o.trace_file.empty()) {
        trace.reset(std::fopen(o.trace_file.c_str(), "wb"));
        if (!trace) throw std::runtime_error(o.trace_file + ": cannot create trace file");
        std::fputs(trace_csv_header().c_str(), trace.get());
    }

    g_stop_requested.store(false);
    std::signal(SIGINT, on_stop_signal);
    std::signal(SIGTERM, on_stop_signal);

    using Clock = std::chrono::steady_clock;
    FixedStepDriver driver = FixedStepDriver::at_rate(config.tick_rate_hz, config.max_catch_up_ticks);
    const std::uint32_t flush_every = static_cast<std::uint32_t>(config.tick_rate_hz / 4);  // ≤ 250 ms lost on a crash
    const std::uint64_t status_every = static_cast<std::uint64_t>(config.tick_rate_hz);
    auto last = Clock::now();
    std::uint64_t k = 0;
    double distance = 0.0;
    float top_speed = 0.0f;
    while (k < total_ticks && !g_stop_requested.load()) {
        std::int32_t due = 1;
        if (!o.fast) {
            const auto now = Clock::now();
            due = driver.advance(std::chrono::duration_cast<std::chrono::nanoseconds>(now - last).count());
            last = now;
        }
        for (std::int32_t i = 0; i < due && k < total_ticks; ++i, ++k) {
            const TickInput input = k < ticks.size() ? ticks[k] : TickInput{};
            const vec3 before = sim.state().root_position;
            if (live) previous = sim.state();
            sim.step(input);
            const PuppetState& s = sim.state();
            const vec3 d = s.root_position - before;
            distance += std::sqrt(static_cast<double>(d.x) * d.x + static_cast<double>(d.z) * d.z);
            top_speed = std::max(top_speed, std::sqrt(s.velocity.x * s.velocity.x + s.velocity.y * s.velocity.y));
            if (log) {
                log->append_tick(input);
                if (log->pending_ticks() >= flush_every) log->flush();
            }
            if (trace) std::fputs(trace_csv_row(s).c_str(), trace.get());
            if (s.tick % status_every == 0) {
                fmt::print("{}\n", status_line(s, static_cast<double>(s.tick) / config.tick_rate_hz, distance));
                std::fflush(stdout);
            }
        }
        if (live && !live->frame(previous, sim.state(), static_cast<float>(driver.alpha()),
                                 status_line(sim.state(), static_cast<double>(sim.state().tick) / config.tick_rate_hz, distance)))
            g_stop_requested.store(true);  // window closed
        if (!o.fast) {
            const auto next = last + std::chrono::nanoseconds(driver.tick_ns - driver.accumulated_ns);
            std::this_thread::sleep_until(next);
        }
    }
    if (log) log->close();
    const PuppetState& s = sim.state();
    fmt::print("{}: {:.1f} s, {} ticks; walked {:.1f} m, top speed {:.2f} m/s; {} catch-up drops; final state hash {:016x}\n",
               g_stop_requested.load() ? "stopped" : "demo finished", static_cast<double>(s.tick) / config.tick_rate_hz,
               s.tick, distance, top_speed, driver.catch_up_cap_hits, hash_state(s));
    return 0;
}

void register_run_command(CLI::App& app, int& exit_code) {
    auto o = std::make_shared<RunOptions>();
    CLI::App* cmd = app.add_subcommand("run", "Run the puppet live (headless demo with a simulated controller by default)");
    cmd->add_option("--config", o->config_file, "TOML file overriding the defaults")->check(CLI::ExistingFile);
    cmd->add_option("--input", o->input, "sim:PROGRAM (a stick program file, or builtin:NAME)");
    cmd->add_option("--render-config", o->render_config_file, "render settings TOML overriding config/render.toml")
        ->check(CLI::ExistingFile);
    cmd->add_option("--display", o->display, "auto|headless|window|kms (auto: a window under X11/Wayland, KMS on a console, else none)")->check(CLI::IsMember({"auto", "headless", "kms", "window"}));
    cmd->add_option("--record", o->record_file, "write the input log here");
    cmd->add_option("--trace", o->trace_file, "per-tick CSV: tick,hash,root_x,root_y,root_z");
    cmd->add_option("--duration", o->duration_s, "seconds to run (default: until the program ends)")->check(CLI::Range(0.0, 86400.0));
    cmd->add_flag("--fast", o->fast, "do not pace ticks in real time");
    on_parsed(cmd, exit_code, [o] { return run_command(*o); });
}

}  // namespace marionette
