#include "app/live/pipeline.hpp"

#include <fmt/format.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>

#include <cmath>
#include <stdexcept>
#include <thread>

#include "app/live/clock.hpp"
#include "app/config/config.hpp"
#include "app/live/config_watcher.hpp"
#include "app/io/files.hpp"
#include "app/graph/graph_files.hpp"
#include "app/live/realtime.hpp"
#include "app/eval/replay.hpp"
#include "input/input_thread.hpp"
#include "render_es/interpolate.hpp"
#include "render_es/view.hpp"
#include "runtime/math/det_math.hpp"
#include "runtime/errors/import_error.hpp"
#include "runtime/sim/fixed_step.hpp"

namespace marionette {

static_assert(std::is_same_v<InputRing, input::InputRing>, "the device input thread pushes into the pipeline's ring");

// ---------------------------------------------------------------- simulation

SimulationLoop::SimulationLoop(const SimConfig& config, PipelineShared& shared,
                               std::vector<ScheduledConfigChange> scheduled, bool wait_when_full)
    : sim_(config), shared_(shared), scheduled_(std::move(scheduled)), wait_when_full_(wait_when_full) {}

void SimulationLoop::apply(const SimConfig& config, TickRecord::ConfigSource source, std::uint32_t id) {
    // The watcher refused structural changes already, and a log's changes were
    // checked when it was decoded, so retune cannot fail here. It copies the
    // configuration into the simulation's; the terrain is structural, so its
    // arrays have the same sizes and the copy reuses their storage.
    if (!sim_.retune(config).ok()) return;
    ++config_changes_;
    record_.kind = TickRecord::Kind::config_change;
    record_.config_source = source;
    record_.config_id = id;
    push(record_);
}

void SimulationLoop::push(const TickRecord& record) {
    while (!shared_.records.try_push(record)) {
        if (!wait_when_full_) {
            shared_.counters.records_dropped.fetch_add(1, std::memory_order_relaxed);
            return;
        }
        if (shared_.stop.load(std::memory_order_relaxed)) return;
        std::this_thread::yield();
    }
}

void SimulationLoop::run_tick(std::int64_t tick_time_ns, std::int64_t now_ns) {
    // Tick boundary: configuration changes first, so the log can place them.
    const std::uint64_t k = sim_.state().tick;
    while (next_scheduled_ < scheduled_.size() && scheduled_[next_scheduled_].before_tick <= k) {
        apply(scheduled_[next_scheduled_].config, TickRecord::ConfigSource::recorded,
              static_cast<std::uint32_t>(next_scheduled_));
        ++next_scheduled_;
    }
    if (shared_.config_updates.take())
        apply(shared_.config_updates.front().config, TickRecord::ConfigSource::live_edit,
              shared_.config_updates.front().version);

    // The oldest sample due has waited longest: it is this tick's worst latency.
    if (const TimedInput* oldest = shared_.input_ring.peek(); oldest && oldest->timestamp_ns <= tick_time_ns)
        if (now_ns - oldest->timestamp_ns > latency_window_max_ns_) latency_window_max_ns_ = now_ns - oldest->timestamp_ns;
    const TickInput input = assembler_.assemble(shared_.input_ring, tick_time_ns, now_ns, latency_);
    if ((k + 1) % static_cast<std::uint64_t>(sim_.config().tick_rate_hz) == 0) {
        shared_.counters.input_latency_max_ns.store(latency_window_max_ns_, std::memory_order_relaxed);
        latency_window_max_ns_ = 0;
    }

    StateFrame& frame = shared_.states.back();
    frame.previous = sim_.state();
    sim_.step(input);
    const PuppetState& now = sim_.state();
    frame.current = now;
    frame.current_time_ns = tick_time_ns;
    frame.connected = assembler_.connected();
    frame.tick_ns = 1'000'000'000 / sim_.config().tick_rate_hz;
    shared_.states.publish();

    record_.kind = TickRecord::Kind::tick;
    record_.connected = assembler_.connected();
    record_.tick = now.tick;
    record_.hash = hash_state(now);
    record_.input = input;
    record_.root_position = {now.root_position.x, now.root_position.y, now.root_position.z};
    record_.velocity = {now.velocity.x, now.velocity.y};
    record_.heading = now.heading;
    push(record_);
}

// ---------------------------------------------------------------- render

vec3 FrameLoop::run_frame(std::int64_t frame_time_ns) {
    if (shared_.states.take()) has_state_ = true;
    if (!has_state_) return vec3(0.0f);
    const StateFrame& f = shared_.states.front();
    // Render one tick behind: at the moment `current` was due, show `previous`,
    // and reach `current` one tick later.
    double alpha = static_cast<double>(frame_time_ns - f.current_time_ns) / static_cast<double>(f.tick_ns);
    alpha = alpha < 0.0 ? 0.0 : (alpha > 1.0 ? 1.0 : alpha);
    alpha_ = alpha;
    const float a = static_cast<float>(alpha);
    const size_t n = static_cast<size_t>(f.current.joint_count);
    for (size_t j = 0; j < n; ++j) joints_[j] = lerp(f.previous.model_positions[j], f.current.model_positions[j], a);
    return lerp(f.previous.root_position, f.current.root_position, a);
}

// ---------------------------------------------------------------- input scripts

InputScript script_from_program(const StickProgram& program, int rate, const std::vector<UnplugWindow>& unplugged) {
    const std::vector<TickInput> samples = render_stick_program(program, rate);
    const std::int64_t period = 1'000'000'000 / rate;
    auto to_ns = [](double s) { return static_cast<std::int64_t>(std::llround(s * 1e9)); };
    auto is_unplugged = [&](std::int64_t t) {
        for (const UnplugWindow& w : unplugged)
            if (t >= to_ns(w.at_s) && t < to_ns(w.at_s + w.for_s)) return true;
        return false;
    };
    InputScript script;
    script.stamp_when_read = true;
    script.events.reserve(samples.size() + 2 * unplugged.size() + 2);
    bool was_unplugged = false;
    // Sample n (one past the program) is the controller left at rest.
    for (size_t i = 0; i <= samples.size(); ++i) {
        const std::int64_t t = static_cast<std::int64_t>(i) * period;
        const bool gone = is_unplugged(t);
        TimedInput e;
        e.timestamp_ns = t;
        if (gone && !was_unplugged) {
            e.connected = false;
            script.events.push_back(e);
        } else if (!gone) {
            e.input = i < samples.size() ? samples[i] : TickInput{};
            script.events.push_back(e);
        }
        was_unplugged = gone;
    }
    // Windows that outlast the program end with the controller back, at rest.
    std::int64_t last = script.events.empty() ? 0 : script.events.back().timestamp_ns;
    for (const UnplugWindow& w : unplugged) {
        const std::int64_t back = to_ns(w.at_s + w.for_s);
        if (back > last && !is_unplugged(back) && was_unplugged) {
            TimedInput e;
            e.timestamp_ns = back;
            script.events.push_back(e);
            last = back;
            was_unplugged = false;
        }
    }
    return script;
}

InputScript script_from_log(const DecodedInputLog& log, std::int64_t tick_ns) {
    InputScript script;
    script.stamp_when_read = false;
    script.events.reserve(log.ticks.size());
    for (size_t k = 0; k < log.ticks.size(); ++k) {
        TimedInput e;
        e.timestamp_ns = static_cast<std::int64_t>(k) * tick_ns + 1;  // after tick k−1's time, by tick k's
        e.input = log.ticks[k];
        script.events.push_back(e);
    }
    return script;
}

// ---------------------------------------------------------------- threads

namespace {

void input_thread(PipelineShared& sh, const InputScript& script, std::int64_t t0, bool virtual_time) {
    InputRingWriter<InputRing> writer(sh.input_ring);
    for (const TimedInput& event : script.events) {
        if (sh.stop.load(std::memory_order_relaxed)) break;
        TimedInput sample = event;
        sample.timestamp_ns = t0 + event.timestamp_ns;
        if (virtual_time) {
            // Nothing is real-time: wait for room rather than drop.
            while (!sh.input_ring.try_push(sample)) {
                if (sh.stop.load(std::memory_order_relaxed)) return;
                std::this_thread::yield();
            }
            sh.input_watermark_ns.store(sample.timestamp_ns, std::memory_order_release);
            continue;
        }
        if (!sleep_until_ns_or_stop(sample.timestamp_ns, sh.stop)) break;
        if (script.stamp_when_read) sample.timestamp_ns = monotonic_ns();
        if (sample.connected) writer.push(sample);
        else writer.push_disconnect(sample.timestamp_ns);
        if (!script.stamp_when_read) sh.input_watermark_ns.store(t0 + event.timestamp_ns, std::memory_order_release);
        sh.counters.samples_pushed.store(writer.pushed(), std::memory_order_relaxed);
        sh.counters.samples_dropped.store(writer.dropped(), std::memory_order_relaxed);
    }
    // A disconnect marker still waiting for room goes in before we leave.
    while (!writer.flush_pending() && !sh.stop.load(std::memory_order_relaxed)) sleep_until_ns(monotonic_ns() + 1'000'000);
    if (virtual_time) sh.counters.samples_pushed.store(script.events.size(), std::memory_order_relaxed);
    sh.input_done.store(true, std::memory_order_release);
}

struct SimulationThreadResult {
    TickTimeHistogram tick_time;
    std::uint64_t catch_up_drops = 0;
};

// `wait_for_input`: every sample up to a tick's time must be in the ring before
// the tick runs (virtual time, and recordings replayed live, which stay exact
// even when the input thread is descheduled for a moment).
void simulation_thread(PipelineShared& sh, SimulationLoop& loop, std::uint64_t total_ticks, std::int64_t t0,
                       bool virtual_time, bool wait_for_input, SimulationThreadResult& result) {
    set_simulation_float_mode();
    const SimConfig& config = loop.simulation().config();
    FixedStepDriver driver = FixedStepDriver::at_rate(config.tick_rate_hz, config.max_catch_up_ticks);
    const std::int64_t tick_ns = driver.tick_ns;
    const std::uint64_t ticks_per_second = static_cast<std::uint64_t>(config.tick_rate_hz);
    std::int64_t sim_time = t0;  // the time of the last tick run
    std::int64_t last_wake = t0;
    std::int64_t window_tick_max = 0;
    std::uint64_t ticks = 0;
    auto run_one = [&](std::int64_t now) {
        sim_time += tick_ns;
        const std::int64_t start = virtual_time ? monotonic_ns() : now;
        loop.run_tick(sim_time, virtual_time ? sim_time : start);
        const std::int64_t took = monotonic_ns() - start;
        result.tick_time.add(took);
        if (took > window_tick_max) window_tick_max = took;
        if (++ticks % ticks_per_second == 0) {
            sh.counters.tick_time_max_ns.store(window_tick_max, std::memory_order_relaxed);
            window_tick_max = 0;
        }
    };
    while (ticks < total_ticks && !sh.stop.load(std::memory_order_relaxed)) {
        if (virtual_time) {
            // Wait until every sample up to this tick's time is in the ring.
            while (sh.input_watermark_ns.load(std::memory_order_acquire) < sim_time + tick_ns &&
                   !sh.input_done.load(std::memory_order_acquire) && !sh.stop.load(std::memory_order_relaxed))
                std::this_thread::yield();
            run_one(0);
            continue;
        }
        if (!sleep_until_ns_or_stop(sim_time + tick_ns, sh.stop)) break;
        const std::int64_t now = monotonic_ns();
        driver.max_catch_up_ticks = loop.simulation().config().max_catch_up_ticks;  // live-tunable
        const std::int64_t dropped_before = driver.dropped_ns;
        const std::int32_t due = driver.advance(now - last_wake);
        last_wake = now;
        if (driver.dropped_ns != dropped_before) {
            // Fell too far behind: skip the backlog in time instead of spiralling.
            sim_time += driver.dropped_ns - dropped_before;
            sh.counters.catch_up_drops.store(driver.catch_up_cap_hits, std::memory_order_relaxed);
        }
        for (std::int32_t i = 0; i < due && ticks < total_ticks; ++i) {
            while (wait_for_input && sh.input_watermark_ns.load(std::memory_order_acquire) < sim_time + tick_ns &&
                   !sh.input_done.load(std::memory_order_acquire) && !sh.stop.load(std::memory_order_relaxed))
                sleep_until_ns(monotonic_ns() + 100'000);  // a sleep, not a spin: the input thread may share our CPU
            run_one(monotonic_ns());
        }
    }
    result.catch_up_drops = driver.catch_up_cap_hits;
    sh.simulation_done.store(true, std::memory_order_release);
}

// The GL display, when there is one: made on the render thread (its EGL context
// is current there), which reports how that went before the run starts.
struct DisplayThreadState {
    enum : int { opening, ready, failed };
    std::atomic<int> state{opening};
    std::string error;        // failed: why (written before `state`)
    std::string description;  // ready: the platform
    std::atomic<bool> closed{false};
};

struct RenderInputs {
    const DisplayOptions* display = nullptr;
    const Skeleton* skeleton = nullptr;
    const Terrain* terrain = nullptr;
    float ankle_height = 0.08f;
    int tick_rate_hz = 240;
};

void render_thread(PipelineShared& sh, int frame_rate_hz, bool virtual_time, RenderInputs in,
                   DisplayThreadState& display, FrameTimeHistogram& frame_time) {
    FrameLoop frames(sh);
    std::unique_ptr<render::View> view;
    if (in.display->gl) {
        try {
            view = std::make_unique<render::View>(in.display->platform, in.display->settings, *in.skeleton, *in.terrain);
            display.description = view->platform().description();
            display.state.store(DisplayThreadState::ready, std::memory_order_release);
        } catch (const std::exception& e) {
            display.error = e.what();
            display.state.store(DisplayThreadState::failed, std::memory_order_release);
            return;
        }
    } else {
        display.state.store(DisplayThreadState::ready, std::memory_order_release);
    }
    // Everything a GL frame needs, made once.
    PuppetState drawn{};
    render::DebugOverlay overlay{};
    std::array<char, 256> hud{};
    const bool paced_by_display = view && view->platform().kind() != render::PlatformKind::headless &&
                                  in.display->platform.vsync;
    const std::int64_t period = 1'000'000'000 / frame_rate_hz;
    std::int64_t deadline = monotonic_ns() + period;
    std::int64_t window_max = 0;
    std::uint64_t count = 0;
    std::uint64_t missed = 0;
    volatile float sink = 0.0f;  // keeps the headless frame's work from being optimised away
    while (!sh.stop.load(std::memory_order_relaxed) && !sh.simulation_done.load(std::memory_order_acquire)) {
        // A window or KMS presents on vblank, which paces us; else our own deadline does.
        if (!(paced_by_display && frames.has_state()) &&
            !sleep_until_ns_or_stop(virtual_time ? monotonic_ns() + 1'000'000 : deadline, sh.stop))
            break;
        const std::int64_t start = monotonic_ns();
        const std::int64_t at = virtual_time ? sh.states.front().current_time_ns : start;
        sink = sink + frames.run_frame(at).x;
        if (view && frames.has_state()) {
            const StateFrame& pair = frames.state_pair();
            render::interpolate_state(pair.previous, pair.current, static_cast<float>(frames.alpha()), drawn);
            render::feet_overlay_from_state(drawn, *in.terrain, in.ankle_height, overlay);
            const PipelineCounters& c = sh.counters;
            const float speed = std::sqrt(drawn.velocity.x * drawn.velocity.x + drawn.velocity.y * drawn.velocity.y);
            // The stats overlay, formatted into fixed space (no allocation in the frame).
            const auto n = fmt::format_to_n(
                hud.data(), hud.size() - 1,
                "t {:.1f} s  {:.2f} m/s{}  tick max {:.0f} us  input->tick max {:.1f} ms  dropped {}  missed frames {}",
                static_cast<double>(drawn.tick) / in.tick_rate_hz, speed,
                frames.state_pair().connected ? "" : "  [no controller: idling]",
                c.tick_time_max_ns.load(std::memory_order_relaxed) / 1e3,
                c.input_latency_max_ns.load(std::memory_order_relaxed) / 1e6,
                c.samples_dropped.load(std::memory_order_relaxed), c.missed_frames.load(std::memory_order_relaxed));
            const render::FrameResult r = view->frame(drawn, overlay, std::string_view(hud.data(), n.size),
                                                      static_cast<float>(period) / 1e9f);
            if (r.events.close_requested) {
                display.closed.store(true, std::memory_order_release);
                break;
            }
        }
        const std::int64_t end = monotonic_ns();
        frame_time.add(end - start);
        if (end - start > window_max) window_max = end - start;
        sh.counters.frames.store(++count, std::memory_order_relaxed);
        if (count % static_cast<std::uint64_t>(frame_rate_hz) == 0) {
            sh.counters.frame_time_max_ns.store(window_max, std::memory_order_relaxed);
            window_max = 0;
        }
        deadline += period;
        if (!virtual_time && end > deadline) {
            // Woke or worked past the next vblank: those frames were never shown.
            const std::int64_t late = (end - deadline) / period + 1;
            missed += static_cast<std::uint64_t>(late);
            deadline += late * period;
            sh.counters.missed_frames.store(missed, std::memory_order_relaxed);
        }
    }
}

const char* activity(float speed) {
    if (speed < 0.05f) return "standing";
    if (speed < 2.0f) return "walking";
    return "running";
}

// "table.key = value" lines of a serialized configuration, for change notices.
std::vector<std::pair<std::string, std::string>> config_lines(const SimConfig& config) {
    std::vector<std::pair<std::string, std::string>> out;
    const std::string text = serialize_config(config);
    std::string table;
    size_t at = 0;
    while (at < text.size()) {
        size_t end = text.find('\n', at);
        if (end == std::string::npos) end = text.size();
        const std::string line = text.substr(at, end - at);
        at = end + 1;
        if (line.size() > 2 && line.front() == '[') table = line.substr(1, line.size() - 2);
        else if (const size_t eq = line.find(" = "); eq != std::string::npos)
            out.emplace_back(table + "." + line.substr(0, eq), line.substr(eq + 3));
    }
    return out;
}

std::string config_diff(const SimConfig& from, const SimConfig& to) {
    const auto a = config_lines(from);
    const auto b = config_lines(to);
    std::string out;
    for (size_t i = 0; i < a.size() && i < b.size(); ++i)
        if (a[i].second != b[i].second)
            out += (out.empty() ? "" : ", ") + a[i].first + " " + a[i].second + " → " + b[i].second;
    return out.empty() ? "no change" : out;
}

// Ok when the [realtime] thread settings are the same; they apply only at start.
Outcome realtime_unchanged(const SimConfig& a, const SimConfig& b) {
    const std::int32_t SimConfig::*const keys[] = {&SimConfig::input_priority, &SimConfig::simulation_priority,
                                                   &SimConfig::render_priority, &SimConfig::input_cpu,
                                                   &SimConfig::simulation_cpu, &SimConfig::render_cpu,
                                                   &SimConfig::lock_memory};
    for (auto key : keys)
        if (a.*key != b.*key) return Outcome::failure("realtime (thread settings)");
    return Outcome::success();
}

// The writer's side of live tuning: validate an edit and hand it to the simulation.
struct LiveTuning {
    std::unique_ptr<ConfigWatcher> watcher;
    SimConfig published;       // the newest configuration handed over
    // Only its fixed-after-start part is read (motion_source_allowed), so this
    // thread may ask it while the simulation thread steps.
    const Simulation* simulation = nullptr;
    std::uint32_t version = 0;
    // Every configuration handed over, by version − 1: the simulation names the
    // one it applied and the writer logs it (edits come at human pace).
    std::vector<SimConfig> history;
    std::int64_t dirty_since = -1;

    void reload(PipelineShared& sh, std::FILE* err) {
        SimConfig next;
        try {
            next = load_config(watcher->path());
        } catch (const ConfigError& e) {
            fmt::print(err, "config: {}; keeping the previous configuration\n", e.what());
            return;
        }
        Outcome kept = structure_unchanged(published, next);
        if (kept.ok()) kept = realtime_unchanged(published, next);
        if (kept.ok() && simulation) kept = simulation->motion_source_allowed(next);
        if (!kept.ok()) {
            fmt::print(err, "config: {}: {} cannot change while running (restart to apply it); keeping the previous configuration\n",
                       watcher->path(), kept.problem());
            return;
        }
        if (serialize_config(next) == serialize_config(published)) return;
        published = next;
        history.push_back(next);
        ConfigUpdate& update = sh.config_updates.back();
        update.version = ++version;
        update.config = next;
        sh.config_updates.publish();
    }
};

struct ThreadGuard {
    std::vector<std::thread*> threads;
    PipelineShared& shared;
    ~ThreadGuard() {
        shared.stop.store(true);
        for (std::thread* t : threads)
            if (t->joinable()) t->join();
    }
};

}  // namespace

// ---------------------------------------------------------------- the run

PipelineResult run_pipeline(const PipelineOptions& o) {
    PipelineResult result;
    const SimConfig& config = o.config;
    auto shared = std::make_unique<PipelineShared>();
    PipelineShared& sh = *shared;

    // Everything that allocates happens here, before the threads start.
    set_simulation_float_mode();
    auto loop = std::make_unique<SimulationLoop>(config, sh, o.scheduled_changes, o.virtual_time);
    if (o.graph) attach_motion_graph(loop->simulation_before_start(), o.graph);
    std::unique_ptr<InputLogFile> log;
    if (!o.record_file.empty()) {
        InputLogHeader header;
        header.tick_rate_hz = static_cast<std::uint32_t>(config.tick_rate_hz);
        header.clip_data_hash = loop->simulation().clip_data_hash();
        header.config_text = serialize_config(config);
        log = std::make_unique<InputLogFile>(o.record_file, header);
    }
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> trace(nullptr, &std::fclose);
    if (!o.trace_file.empty()) {
        trace.reset(std::fopen(o.trace_file.c_str(), "wb"));
        if (!trace) throw std::runtime_error(o.trace_file + ": cannot create trace file");
        std::fputs(trace_csv_header().c_str(), trace.get());
    }
    LiveTuning tuning;
    tuning.published = config;
    tuning.simulation = &loop->simulation();
    if (!o.watch_config_file.empty()) tuning.watcher = std::make_unique<ConfigWatcher>(o.watch_config_file);

    std::string realtime_failed;
    auto note_failure = [&](const Outcome& applied) {
        if (!applied.ok()) realtime_failed += (realtime_failed.empty() ? "" : "; ") + applied.problem();
    };
    if (config.lock_memory) note_failure(lock_all_memory());

    // Only this thread takes SIGINT/SIGTERM: the workers start with them blocked.
    sigset_t stop_signals, previous_mask;
    sigemptyset(&stop_signals);
    sigaddset(&stop_signals, SIGINT);
    sigaddset(&stop_signals, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &stop_signals, &previous_mask);

    SimulationThreadResult sim_result;
    DisplayThreadState display;
    RenderInputs render_inputs{&o.display, &loop->simulation().skeleton(), &loop->simulation().terrain(),
                               config.ankle_height, config.tick_rate_hz};
    std::thread sim_thread, in_thread, gfx_thread;
    auto device = std::make_unique<input::InputThread>();  // stopped (joined) by its destructor
    ThreadGuard guard{{&sim_thread, &in_thread, &gfx_thread}, sh};
    std::int64_t wall_start = 0;
    try {
        // The render thread first: the display must open before the clock starts.
        gfx_thread = std::thread(render_thread, std::ref(sh), o.frame_rate_hz, o.virtual_time, render_inputs,
                                 std::ref(display), std::ref(result.frame_time));
        while (display.state.load(std::memory_order_acquire) == DisplayThreadState::opening)
            sleep_until_ns(monotonic_ns() + 1'000'000);
        if (display.state.load(std::memory_order_acquire) == DisplayThreadState::failed) {
            gfx_thread.join();
            throw render::PlatformError(display.error);
        }
        result.display_description = display.description;
        wall_start = monotonic_ns();
        const std::int64_t t0 = o.virtual_time ? 0 : wall_start + 20'000'000;  // let the threads start first
        // The input thread before the simulation thread: a device backend that
        // cannot open its pad fails here, before any tick runs or is recorded.
        if (o.device) {
            if (const Outcome started = device->start(sh.input_ring, *o.device); !started.ok())
                throw ImportError("--input " + o.device->backend, 0, started.problem());
            result.input_description = device->backend_description();
        } else {
            in_thread = std::thread(input_thread, std::ref(sh), std::cref(o.script), t0, o.virtual_time);
        }
        sim_thread = std::thread(simulation_thread, std::ref(sh), std::ref(*loop), o.total_ticks, t0, o.virtual_time,
                                 !o.script.stamp_when_read, std::ref(sim_result));
    } catch (...) {
        pthread_sigmask(SIG_SETMASK, &previous_mask, nullptr);
        throw;
    }
    pthread_sigmask(SIG_SETMASK, &previous_mask, nullptr);
    // Virtual time waits by spinning: never under SCHED_FIFO, where a spinning
    // thread would starve the writer it waits for.
    const bool fifo = !o.virtual_time;
    note_failure(apply_thread_settings(o.device ? device->thread() : in_thread, "mario-input", fifo ? config.input_priority : 0, config.input_cpu));
    note_failure(apply_thread_settings(sim_thread, "mario-sim", fifo ? config.simulation_priority : 0, config.simulation_cpu));
    note_failure(apply_thread_settings(gfx_thread, "mario-render", fifo ? config.render_priority : 0, config.render_cpu));
    if (!realtime_failed.empty()) {
        result.realtime_warning = realtime_failed;
        fmt::print(o.err, "warning: real-time settings not permitted ({}); running with normal scheduling\n",
                   realtime_failed);
    }

    // The writer: this thread drains the records into the log, the trace and the
    // status line, and watches the configuration file.
    const std::uint32_t flush_ticks = static_cast<std::uint32_t>(config.tick_rate_hz / 4);
    const std::uint64_t ticks_per_second = static_cast<std::uint64_t>(config.tick_rate_hz);
    std::int64_t last_flush = monotonic_ns();
    std::int64_t stop_seen = -1;
    bool connected = true;
    vec3 previous_root = loop->simulation().state().root_position;
    SimConfig logged_config = config;
    std::string row;
    auto handle = [&](const TickRecord& r) {
        const double seconds = static_cast<double>(r.tick) / config.tick_rate_hz;
        if (r.kind == TickRecord::Kind::config_change) {
            const SimConfig& applied = r.config_source == TickRecord::ConfigSource::recorded
                                           ? o.scheduled_changes.at(r.config_id).config
                                           : tuning.history.at(r.config_id - 1);
            if (log) log->append_config_change(serialize_config(applied));
            fmt::print(o.out, "[{:6.1f} s] config: applied before tick {}: {}\n", seconds, r.tick,
                       config_diff(logged_config, applied));
            logged_config = applied;
            return;
        }
        result.ticks = r.tick;
        if (log) {
            log->append_tick(r.input);
            if (log->pending_ticks() >= flush_ticks) {
                log->flush();  // a chunk per 250 ms of ticks: kill -9 loses at most that
                last_flush = monotonic_ns();
            }
        }
        const vec3 root(r.root_position[0], r.root_position[1], r.root_position[2]);
        if (trace && std::fputs(trace_csv_row(r.tick, r.hash, root).c_str(), trace.get()) < 0)
            throw std::runtime_error(o.trace_file + ": write failed");
        const vec3 d = root - previous_root;
        previous_root = root;
        result.distance_m += std::sqrt(static_cast<double>(d.x) * d.x + static_cast<double>(d.z) * d.z);
        const float speed = std::sqrt(r.velocity[0] * r.velocity[0] + r.velocity[1] * r.velocity[1]);
        if (speed > result.top_speed) result.top_speed = speed;
        if (r.connected != connected) {
            connected = r.connected;
            if (connected) fmt::print(o.out, "[{:6.1f} s] controller connected: resuming\n", seconds);
            else fmt::print(o.out, "[{:6.1f} s] controller disconnected: the puppet idles until one is connected\n", seconds);
            std::fflush(o.out);
        }
        if (o.status_lines && r.tick % ticks_per_second == 0) {
            const PipelineCounters& c = sh.counters;
            fmt::print(o.out,
                       "[{:6.1f} s] {:<8} {:4.2f} m/s  heading {:4.0f}°  at ({:6.2f}, {:6.2f})  walked {:5.1f} m | "
                       "tick max {:.0f} µs  input→tick max {:.1f} ms  frame max {:.0f} µs  frames {} (missed {})  "
                       "dropped {}{}\n",
                       seconds, connected ? activity(speed) : "idle", speed, r.heading * det::kRadToDeg,
                       root.x, root.z, result.distance_m,
                       c.tick_time_max_ns.load(std::memory_order_relaxed) / 1e3,
                       c.input_latency_max_ns.load(std::memory_order_relaxed) / 1e6,
                       c.frame_time_max_ns.load(std::memory_order_relaxed) / 1e3,
                       c.frames.load(std::memory_order_relaxed), c.missed_frames.load(std::memory_order_relaxed),
                       c.samples_dropped.load(std::memory_order_relaxed), connected ? "" : "  [no controller]");
            std::fflush(o.out);
        }
    };
    TickRecord record;
    for (;;) {
        const bool finished = sh.simulation_done.load(std::memory_order_acquire);
        while (sh.records.try_pop(record)) handle(record);
        const std::int64_t now = monotonic_ns();
        // And by the clock, should ticks come slowly; virtual time flushes by tick
        // count only, so its logs are byte-for-byte repeatable.
        if (log && !o.virtual_time && log->pending_ticks() > 0 && now - last_flush >= 200'000'000) {
            log->flush();
            last_flush = now;
        }
        if (finished) break;  // simulation_done was read before the last drain
        if (stop_seen < 0 && o.stop_request && o.stop_request->load()) {
            stop_seen = now;
            result.stopped = true;
            sh.stop.store(true);
        }
        if (o.device) {
            // The backend keeps its own counters; the status line reads these.
            const input::InputThreadStats st = device->stats();
            sh.counters.samples_pushed.store(st.samples, std::memory_order_relaxed);
            sh.counters.samples_dropped.store(st.ring_dropped, std::memory_order_relaxed);
        }
        if (!result.display_closed && display.closed.load(std::memory_order_acquire)) {
            result.display_closed = true;  // closing the window ends the run normally
            sh.stop.store(true);
        }
        if (tuning.watcher) {
            pollfd p{tuning.watcher->fd(), POLLIN, 0};
            if (poll(&p, 1, 5) > 0 && tuning.watcher->read_events()) tuning.dirty_since = monotonic_ns();
            // Editors write in steps: read the file once it has been quiet for 100 ms.
            if (tuning.dirty_since >= 0 && monotonic_ns() - tuning.dirty_since >= 100'000'000) {
                tuning.dirty_since = -1;
                tuning.reload(sh, o.err);
            }
        } else {
            sleep_until_ns(monotonic_ns() + 5'000'000);
        }
    }
    sh.stop.store(true);
    if (o.device) {
        const input::InputThreadStats st = device->stats();
        sh.counters.samples_pushed.store(st.samples);
        sh.counters.samples_dropped.store(st.ring_dropped);
        device->stop();
    }
    for (std::thread* t : guard.threads)
        if (t->joinable()) t->join();
    while (sh.records.try_pop(record)) handle(record);
    if (log) log->close();
    if (trace) {
        if (std::fclose(trace.release()) != 0) throw std::runtime_error(o.trace_file + ": write failed");
    }
    const std::int64_t end = monotonic_ns();
    if (result.stopped) {
        std::int64_t from = stop_seen;
        if (o.stop_request_time_ns && o.stop_request_time_ns->load() > 0) from = o.stop_request_time_ns->load();
        result.shutdown_ms = static_cast<double>(end - from) / 1e6;
    }
    result.wall_s = static_cast<double>(end - wall_start) / 1e9;
    result.final_state = loop->simulation().state();
    result.ticks = result.final_state.tick;
    result.final_hash = hash_state(result.final_state);
    result.input_latency = loop->input_latency();
    result.tick_time = sim_result.tick_time;
    result.samples_pushed = sh.counters.samples_pushed.load();
    result.samples_dropped = sh.counters.samples_dropped.load();
    result.frames = sh.counters.frames.load();
    result.missed_frames = sh.counters.missed_frames.load();
    result.catch_up_drops = sim_result.catch_up_drops;
    result.records_dropped = sh.counters.records_dropped.load();
    result.config_changes = loop->config_changes();
    result.disconnects = loop->assembler().disconnects();
    result.reconnects = loop->assembler().reconnects();
    return result;
}

}  // namespace marionette
