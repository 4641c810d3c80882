#include "app/live/pipeline.hpp"
#include "app/io/log.hpp"

#include <fmt/format.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <thread>

#include "app/live/clock.hpp"
#include "app/config/config.hpp"
#include "app/live/config_watcher.hpp"
#include "app/io/files.hpp"
#include "app/eval/log_provenance.hpp"
#include "app/graph/graph_files.hpp"
#include "app/live/realtime.hpp"
#include "app/live/service_notify.hpp"
#include "app/ui/tuning_ui.hpp"
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
    // configuration into the simulation's; only a terrain edit (rare, made by
    // hand) grows the terrain's arrays, every other change reuses their storage.
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
    const TickInput pad = assembler_.assemble(shared_.input_ring, tick_time_ns, now_ns, latency_);
    if (const std::uint32_t event = ui::press_event(previous_buttons_, pad.buttons); event != 0)
        (void)shared_.pad_events.try_push(ui::PadPress{event, k + 1});  // full: nobody is reading (no display), drop it
    previous_buttons_ = pad.buttons;
    // The tuning UI is open: the pad drives it, the puppet gets (and the log records) rest.
    // In the spline editor's d-pad mode the sticks still walk it (the puppet keeps walking while a key moves).
    TickInput input = pad;
    if (shared_.ui_captures_input.load(std::memory_order_relaxed)) {
        input = TickInput{};
        if (shared_.ui_passes_sticks.load(std::memory_order_relaxed)) {
            input.left_x = pad.left_x, input.left_y = pad.left_y;
            input.right_x = pad.right_x, input.right_y = pad.right_y;
        }
    }
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
    input_stamps_[now.tick % kTickStampHistory] = {now.tick, assembler_.last_samples(), assembler_.last_oldest_ns(),
                                                   assembler_.last_newest_ns(), now_ns};
    frame.recent_inputs = input_stamps_;
    frame.pad = pad;
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
    // s: how far past the current tick's time this frame is, in ticks.
    double s = static_cast<double>(frame_time_ns - f.current_time_ns) / static_cast<double>(f.tick_ns);
    s = s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
    switch (mode_) {
        case Interpolation::interpolate:
            // One tick behind: at the moment `current` was due, show `previous`,
            // and reach `current` one tick later.
            alpha_ = s;
            shown_tick_ = s >= 1.0 ? f.current.tick : f.previous.tick;
            break;
        case Interpolation::extrapolate:
            alpha_ = 1.0 + s;
            shown_tick_ = f.current.tick;
            break;
        case Interpolation::latest:
            alpha_ = 1.0;
            shown_tick_ = f.current.tick;
            break;
    }
    const float a = static_cast<float>(alpha_);
    const size_t n = static_cast<size_t>(f.current.joint_count);
    for (size_t j = 0; j < n; ++j) joints_[j] = lerp(f.previous.model_positions[j], f.current.model_positions[j], a);
    return lerp(f.previous.root_position, f.current.root_position, a);
}

void FrameLoop::presented(std::int64_t present_ns) {
    if (!has_state_ || shown_tick_ <= last_presented_tick_) return;  // nothing new reached this frame
    const TickStampHistory& recent = shared_.states.front().recent_inputs;
    // The ticks this frame is the first to show; those older than the history are gone.
    std::uint64_t from = last_presented_tick_ + 1;
    if (shown_tick_ - last_presented_tick_ > kTickStampHistory) from = shown_tick_ - kTickStampHistory + 1;
    last_presented_tick_ = shown_tick_;
    bool any = false;
    std::int64_t oldest = 0, newest = 0;
    for (std::uint64_t t = from; t <= shown_tick_; ++t) {
        const TickInputStamps& e = recent[t % kTickStampHistory];
        if (e.tick != t || e.samples == 0) continue;
        if (!any) oldest = e.oldest_ns;  // samples come in stamp order: the first tick's oldest is the oldest
        any = true;
        newest = e.newest_ns;
    }
    if (const TickInputStamps& shown = recent[shown_tick_ % kTickStampHistory]; shown.tick == shown_tick_)
        present_.tick_to_present.add(present_ns - shown.ran_ns);
    if (!any) return;
    present_.oldest.add(present_ns - oldest);
    present_.newest.add(present_ns - newest);
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
    // Sample n (one past the program) is the controller left at rest. Like an
    // evdev pad, the controller reports only changes: a sample equal to the one
    // before is not sent (a tick without a new sample keeps the last values and
    // held buttons, so the ticks' inputs are the same), and an idle stick wakes
    // nothing (docs/pipeline.md, "Power").
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
            const bool repeat = !was_unplugged && !script.events.empty() && script.events.back().connected &&
                                script.events.back().input == e.input;
            if (!repeat) script.events.push_back(e);
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
    std::int64_t skipped_ns = 0;           // time skipped by the catch-up cap
    std::int32_t max_ticks_per_wake = 0;   // the longest burst of ticks run for one wake-up
};

// `wait_for_input`: every sample up to a tick's time must be in the ring before
// the tick runs (virtual time, and recordings replayed live, which stay exact
// even when the input thread is descheduled for a moment).
void simulation_thread(PipelineShared& sh, SimulationLoop& loop, std::uint64_t total_ticks, std::int64_t t0,
                       bool virtual_time, bool wait_for_input, std::int64_t stall_ms, SimulationThreadResult& result) {
    set_simulation_float_mode();
    const SimConfig& config = loop.simulation().config();
    FixedStepDriver driver = FixedStepDriver::at_rate(config.tick_rate_hz, config.max_catch_up_ticks);
    const std::int64_t tick_ns = driver.tick_ns;
    const std::uint64_t ticks_per_second = static_cast<std::uint64_t>(config.tick_rate_hz);
    std::int64_t sim_time = t0;  // the time of the last tick run
    std::int64_t last_wake = t0;
    std::int64_t window_tick_max = 0;
    std::uint64_t ticks = 0;
    // A recording played live is consumed on its own schedule (tick k takes
    // exactly sample k, stamped by tick), even after the catch-up cap skipped
    // time; a live controller's samples are consumed by the clock.
    auto consume_time = [&] {
        return wait_for_input ? t0 + static_cast<std::int64_t>(ticks + 1) * tick_ns : sim_time + tick_ns;
    };
    auto run_one = [&](std::int64_t now) {
        const std::int64_t due = consume_time();
        sim_time += tick_ns;
        const std::int64_t start = virtual_time ? monotonic_ns() : now;
        loop.run_tick(due, virtual_time ? sim_time : start);
        const std::int64_t took = monotonic_ns() - start;
        result.tick_time.add(took);
        if (took > window_tick_max) window_tick_max = took;
        sh.counters.simulation_heartbeat.fetch_add(1, std::memory_order_relaxed);
        if (++ticks % ticks_per_second == 0) {
            sh.counters.tick_time_max_ns.store(window_tick_max, std::memory_order_relaxed);
            window_tick_max = 0;
        }
        // The watchdog test's stuck simulation (a test hook, off unless asked).
        if (stall_ms > 0 && ticks == ticks_per_second) sleep_until_ns_or_stop(monotonic_ns() + stall_ms * 1'000'000, sh.stop);
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
        if (due > result.max_ticks_per_wake) result.max_ticks_per_wake = due;
        for (std::int32_t i = 0; i < due && ticks < total_ticks; ++i) {
            while (wait_for_input && sh.input_watermark_ns.load(std::memory_order_acquire) < consume_time() &&
                   !sh.input_done.load(std::memory_order_acquire) && !sh.stop.load(std::memory_order_relaxed))
                sleep_until_ns(monotonic_ns() + 100'000);  // a sleep, not a spin: the input thread may share our CPU
            run_one(monotonic_ns());
        }
    }
    result.catch_up_drops = driver.catch_up_cap_hits;
    result.skipped_ns = driver.dropped_ns;
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
    // The ground drawn, the render thread's once it starts: the start's (copied
    // before, so the thread allocates nothing for it), then each applied edit's.
    Terrain* terrain = nullptr;
    float ankle_height = 0.08f;
    int tick_rate_hz = 240;
    Interpolation interpolation = Interpolation::interpolate;
    std::uint64_t stall_after_frames = 0;  // test hook: PipelineOptions::test_render_stall_ns
    std::int64_t stall_ns = 0;
    const ui::TuningUiOptions* ui = nullptr;  // the tuning UI over the display (null: none)
    const GaitConfig* gait = nullptr;         // the start's, for the render thread's own gait rig
};

// The tuning UI, made on the render thread once the view is open (its GL
// context is current here); null without a display or with [ui] enabled = false.
std::unique_ptr<ui::TuningUi> open_tuning_ui(render::View* view, const RenderInputs& in) {
    if (view == nullptr || in.ui == nullptr) return nullptr;
    auto tuning = std::make_unique<ui::TuningUi>(view->platform(), *in.ui);
    view->set_layer(tuning.get());
    view->platform().set_native_event_hook(tuning.get());
    return tuning;
}

// Before a frame: what the writer accepted, the pad, and whether the puppet gets it.
// Returns whether the UI's working config changed (it adopted an accepted one).
bool feed_tuning_ui(ui::TuningUi* tuning, PipelineShared& sh, const StateFrame& pair) {
    if (tuning == nullptr) return false;
    const bool adopted = sh.accepted_configs.take();
    if (adopted) tuning->adopt(sh.accepted_configs.front());
    tuning->set_puppet_position(pair.current.root_position.x, pair.current.root_position.z);
    // One press a frame, in order: ImGui sees each go down in one frame and up
    // in the next, so a d-pad move and the south press after it stay in order
    // however slow the frames are.
    // While closed only the chord matters: the queue is drained up to it.
    ui::PadPress event{};
    if (!tuning->is_open()) {
        for (ui::PadPress e{}; event.event == 0 && sh.pad_events.try_pop(e);)
            if (e.event & ui::kChordMade) event = e;
    } else if (!tuning->releasing()) {
        (void)sh.pad_events.try_pop(event);
    }
    tuning->feed_pad(pair.pad, pair.current.tick, pair.tick_ns, event, sh.pad_events.peek() == nullptr);
    sh.ui_passes_sticks.store(tuning->is_open() && tuning->spline_pad_mode(), std::memory_order_relaxed);
    sh.ui_captures_input.store(tuning->is_open(), std::memory_order_relaxed);
    return adopted;
}

// Before a frame: a terrain the simulation now walks on replaces the drawn
// ground (the mesh is rebuilt here, on the render thread, once per edit).
void take_applied_terrain(PipelineShared& sh, render::View* view, Terrain& drawn_terrain) {
    if (!sh.applied_terrain.take()) return;
    drawn_terrain = sh.applied_terrain.front();
    if (view != nullptr) view->renderer().set_terrain(drawn_terrain);
}

// After a frame: an edit made in it goes to the writer.
// Returns whether there was one.
bool hand_over_ui_edit(ui::TuningUi* tuning, PipelineShared& sh) {
    if (tuning == nullptr || !tuning->take_edit(sh.ui_edits.back().config)) return false;
    sh.ui_edits.publish();
    return true;
}

// Each frame is stamped when presented: the page flip's vblank time on KMS, after
// the swap in a window, the frame loop's end headless (the frame's own time in
// virtual time); `present` gets the latencies to those stamps.
void render_thread(PipelineShared& sh, int frame_rate_hz, bool virtual_time, RenderInputs in,
                   DisplayThreadState& display, FrameTimeHistogram& frame_time, PresentLatency& present) {
    FrameLoop frames(sh, in.interpolation);
    Terrain& terrain = *in.terrain;
    std::unique_ptr<render::View> view;
    if (in.display->gl) {
        try {
            view = std::make_unique<render::View>(in.display->platform, in.display->settings, *in.skeleton, terrain,
                                                 in.display->body.get());
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
    std::unique_ptr<ui::TuningUi> tuning;
    try {
        tuning = open_tuning_ui(view.get(), in);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "warning: the tuning UI is off: %s\n", e.what());
    }
    // Everything a GL frame needs, made once.
    GaitRig rig = in.gait != nullptr ? make_gait_rig(*in.gait) : GaitRig{};
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
        std::int64_t presented_at = 0;  // the display's own stamp, when it gives one
        if (view && frames.has_state()) {
            const StateFrame& pair = frames.state_pair();
            const float alpha = static_cast<float>(frames.alpha());
            if (alpha > 1.0f) render::extrapolate_state(pair.previous, pair.current, alpha - 1.0f, drawn);
            else render::interpolate_state(pair.previous, pair.current, alpha, drawn);
            take_applied_terrain(sh, view.get(), terrain);
            render::feet_overlay_from_state(drawn, terrain, in.ankle_height, overlay, in.gait != nullptr ? &rig : nullptr);
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
            // The drawn step splines follow the UI's working prototypes (the
            // render thread's own rig; the simulation's is never touched here).
            if (feed_tuning_ui(tuning.get(), sh, pair)) rig = make_gait_rig(tuning->working().sim);
            const render::FrameResult r = view->frame(drawn, overlay, std::string_view(hud.data(), n.size),
                                                      static_cast<float>(period) / 1e9f);
            if (hand_over_ui_edit(tuning.get(), sh)) rig = make_gait_rig(tuning->working().sim);
            if (r.events.close_requested) {
                display.closed.store(true, std::memory_order_release);
                break;
            }
            presented_at = r.present_ns;
        }
        if (in.stall_ns > 0 && count == in.stall_after_frames) sleep_until_ns(monotonic_ns() + in.stall_ns);
        const std::int64_t end = monotonic_ns();
        frames.presented(virtual_time ? at : (presented_at > 0 ? presented_at : end));
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
    present = frames.present_latency();
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
        // A header may carry a comment ("[gait.walk]   # keys ..."): the name ends at its first ']'.
        if (line.size() > 2 && line.front() == '[') table = line.substr(1, line.find(']', 2) - 1);
        else if (const size_t eq = line.find(" = "); eq != std::string::npos)
            out.emplace_back(table + "." + line.substr(0, eq), line.substr(eq + 3));
    }
    return out;
}

std::string config_diff(const SimConfig& from, const SimConfig& to) {
    const auto a = config_lines(from);
    const auto b = config_lines(to);
    std::string out;
    const auto terrain_line = [](const std::string& key) { return key.rfind("terrain", 0) == 0 || key.rfind("[terrain", 0) == 0; };
    for (size_t i = 0; i < a.size() && i < b.size(); ++i)
        if (a[i].second != b[i].second && !terrain_line(a[i].first) && !terrain_line(b[i].first))
            out += (out.empty() ? "" : ", ") + a[i].first + " " + a[i].second + " → " + b[i].second;
    if (!(from.terrain == to.terrain)) {
        // Terrain lines (the table's data) differ in number: counted, not listed.
        const auto count = [](const Terrain& t) {
            return fmt::format("{} box(es), {} slope(s), heightfield {}x{}", t.boxes.size(), t.slopes.size(),
                               t.heightfield.nx, t.heightfield.nz);
        };
        out += (out.empty() ? "" : ", ") + std::string("terrain ") + count(from.terrain) + " → " + count(to.terrain);
    }
    return out.empty() ? "no change" : out;
}

// How often the writer looks at its inputs (records, stop request, config file).
// In real time nothing it does is urgent: a stop signal cuts the wait short (the
// workers block SIGINT/SIGTERM, so it reaches this thread, and poll() is never
// restarted), an edit wakes it through inotify, and the record ring holds 68 s;
// so it waits 50 ms at a time, 20 wake-ups a second (docs/pipeline.md, "Power").
// In virtual time the simulation may be waiting for room in the ring, and once
// stopping the threads are about to end: 5 ms then.
constexpr int kWriterPollMs = 50;
constexpr int kWriterPollShortMs = 5;
// Editors write in steps: a watched file is read once it has been quiet this long.
constexpr std::int64_t kEditQuietNs = 100'000'000;
// A log chunk is written at least this often while ticks are pending (real time).
constexpr std::int64_t kLogFlushIntervalNs = 200'000'000;
// The clock starts this long after the threads are made, so they are running by then.
constexpr std::int64_t kThreadStartLeadNs = 20'000'000;
// How often the starting thread looks whether the display has opened.
constexpr std::int64_t kDisplayOpenPollNs = 1'000'000;

// The writer's side of live tuning: validate an edit and hand it to the simulation.
struct LiveTuning {
    std::unique_ptr<ConfigWatcher> watcher;
    SimConfig published;       // the newest configuration handed over
    RealtimeConfig realtime;   // the thread settings the run started with (fixed)
    TimingConfig timing;       // what the render thread draws (fixed)
    UiConfig ui;               // the tuning UI's lock (fixed)
    // Only its fixed-after-start part is read (motion_source_allowed), so this
    // thread may ask it while the simulation thread steps.
    const Simulation* simulation = nullptr;
    std::uint32_t version = 0;
    // Every configuration handed over, by version − 1: the simulation names the
    // one it applied and the writer logs it (edits come at human pace).
    std::vector<SimConfig> history;
    std::int64_t dirty_since = -1;

    // Waits up to `wait_ms` for an edit of the watched file (without one,
    // just waits) and hands the file over once it has been quiet for kEditQuietNs.
    void wait_and_poll(PipelineShared& sh, std::FILE* err, int wait_ms) {
        if (sh.ui_edits.take()) offer(sh, sh.ui_edits.front().config, "tuning UI", err);
        if (!watcher) {
            poll(nullptr, 0, wait_ms);  // a signal ends it early (EINTR)
            return;
        }
        // An edit in progress is looked at again once it has been quiet long enough.
        if (dirty_since >= 0) wait_ms = std::min<int>(wait_ms, static_cast<int>(kEditQuietNs / 1'000'000));
        pollfd p{watcher->fd(), POLLIN, 0};
        if (poll(&p, 1, wait_ms) > 0 && watcher->read_events()) dirty_since = monotonic_ns();
        if (dirty_since >= 0 && monotonic_ns() - dirty_since >= kEditQuietNs) {
            dirty_since = -1;
            reload(sh, err);
        }
    }

    void reload(PipelineShared& sh, std::FILE* err) {
        AppConfig next;
        try {
            next = load_config(watcher->path());
        } catch (const ParseError& e) {
            // Missing, a directory, unreadable, half-written, invalid (or a terrain
            // file it names is): the run carries on with what it has.
            log_message(LogLevel::warning, fmt::format("config: {}; keeping the previous configuration", e.what()), err);
            return;
        } catch (const std::exception& e) {
            log_message(LogLevel::warning, fmt::format("config: {}: {}; keeping the previous configuration", watcher->path(), e.what()), err);
            return;
        }
        offer(sh, next, watcher->path(), err);
    }

    // A whole configuration from the watched file or the tuning UI: refused when
    // it changes what cannot change while running, else handed to the simulation.
    void offer(PipelineShared& sh, const AppConfig& next, const std::string& origin, std::FILE* err) {
        Outcome kept = structure_unchanged(published, next.sim);
        if (kept.ok() && !(next.realtime == realtime)) kept = Outcome::failure("realtime (thread settings)");
        if (kept.ok() && !(next.timing == timing)) kept = Outcome::failure("timing.interpolation");
        if (kept.ok() && !(next.ui == ui)) kept = Outcome::failure("ui.enabled");
        if (kept.ok() && simulation) kept = simulation->motion_source_allowed(next.sim);
        if (!kept.ok()) {
            log_message(LogLevel::warning, fmt::format("config: {}: {} cannot change while running (restart to apply it); keeping the previous configuration",
                       origin, kept.problem()), err);
            return;
        }
        // The graph build keys are not the tick's: an edit of only those changes nothing here.
        if (serialize_config(next.sim) == serialize_config(published)) return;
        published = next.sim;
        history.push_back(next.sim);
        ConfigUpdate& update = sh.config_updates.back();
        update.version = ++version;
        update.config = next.sim;
        sh.config_updates.publish();
        sh.accepted_configs.back() = next.sim;
        sh.accepted_configs.publish();
    }
};

// The writer's outputs, fed from the simulation's records on the thread that
// called run_pipeline: the input log, the trace, the status and notice lines,
// and the run's distance and top speed.
class RecordWriter {
public:
    RecordWriter(const PipelineOptions& o, const Simulation& sim, PipelineShared& sh, const LiveTuning& tuning,
                 PipelineResult& result)
        : o_(o), sh_(sh), tuning_(tuning), result_(result), tick_rate_hz_(o.config.tick_rate_hz),
          flush_ticks_(static_cast<std::uint32_t>(o.config.tick_rate_hz / 4)), logged_config_(o.config),
          previous_root_(sim.state().root_position), last_flush_(monotonic_ns()) {
        if (!o.record_file.empty()) {
            InputLogHeader header;
            header.tick_rate_hz = static_cast<std::uint32_t>(o.config.tick_rate_hz);
            header.clip_data_hash = sim.clip_data_hash();
            header.config_text = serialize_config(o.config);
            header.provenance = build_provenance();
            header.motion_data = motion_data_reference(o.graph_argument, o.graph.get());
            log_ = std::make_unique<RecordingSink>(RecordingOptions{o.record_file, o.record_rotate_dir, o.record_limits},
                                                   header, o.err);
        }
        if (!o.trace_file.empty()) {
            trace_.reset(std::fopen(o.trace_file.c_str(), "wb"));
            if (!trace_) throw std::runtime_error(o.trace_file + ": cannot create trace file");
            std::fputs(trace_csv_header().c_str(), trace_.get());
        }
    }

    void handle(const TickRecord& r) {
        const double seconds = static_cast<double>(r.tick) / tick_rate_hz_;
        if (r.kind == TickRecord::Kind::config_change) {
            write_config_change(r, seconds);
            return;
        }
        result_.ticks = r.tick;
        const vec3 root(r.root_position[0], r.root_position[1], r.root_position[2]);
        write_tick(r, root);
        const vec3 d = root - previous_root_;
        previous_root_ = root;
        result_.distance_m += std::sqrt(static_cast<double>(d.x) * d.x + static_cast<double>(d.z) * d.z);
        const float speed = std::sqrt(r.velocity[0] * r.velocity[0] + r.velocity[1] * r.velocity[1]);
        if (speed > result_.top_speed) result_.top_speed = speed;
        if (r.connected != connected_) note_connection(r.connected, seconds);
        if (o_.status_lines && r.tick % static_cast<std::uint64_t>(tick_rate_hz_) == 0)
            print_status_line(r, root, speed, seconds);
    }

    // Also by the clock, should ticks come slowly; virtual time flushes by tick
    // count only, so its logs are byte-for-byte repeatable.
    void flush_by_clock(std::int64_t now_ns) {
        if (log_ && !o_.virtual_time && log_->pending_ticks() > 0 && now_ns - last_flush_ >= kLogFlushIntervalNs) {
            log_->flush();
            last_flush_ = now_ns;
        }
    }

    void close() {
        if (log_) {
            if (ticks_since_checkpoint_ > 0) log_->append_checkpoint(last_hash_);  // the state after the last tick
            log_->close();
            result_.recording_stopped = log_->stop_reason();
            result_.record_files = log_->files();
        }
        if (trace_ && std::fclose(trace_.release()) != 0) throw std::runtime_error(o_.trace_file + ": write failed");
    }

private:
    // A recorded change by its index, a live edit by its version.
    void write_config_change(const TickRecord& r, double seconds) {
        const SimConfig& applied = r.config_source == TickRecord::ConfigSource::recorded
                                       ? o_.scheduled_changes.at(r.config_id).config
                                       : tuning_.history.at(r.config_id - 1);
        if (log_) log_->append_config_change(serialize_config(applied));
        if (!(applied.terrain == logged_config_.terrain)) {
            // The simulation walks on it from this tick on: the renderer redraws the ground.
            sh_.applied_terrain.back() = applied.terrain;
            sh_.applied_terrain.publish();
        }
        fmt::print(o_.out, "[{:6.1f} s] config: applied before tick {}: {}\n", seconds, r.tick,
                   config_diff(logged_config_, applied));
        logged_config_ = applied;
    }

    void write_tick(const TickRecord& r, const vec3& root) {
        if (log_) {
            log_->append_tick(r.input);
            last_hash_ = r.hash;
            ticks_since_checkpoint_ = r.tick % kCheckpointIntervalTicks;
            if (ticks_since_checkpoint_ == 0) log_->append_checkpoint(r.hash);
            if (log_->pending_ticks() >= flush_ticks_) {
                log_->flush();  // a chunk per 250 ms of ticks: kill -9 loses at most that
                last_flush_ = monotonic_ns();
            }
        }
        if (trace_ && std::fputs(trace_csv_row(r.tick, r.hash, root).c_str(), trace_.get()) < 0)
            throw std::runtime_error(o_.trace_file + ": write failed");
    }

    void note_connection(bool connected, double seconds) {
        connected_ = connected;
        if (connected) fmt::print(o_.out, "[{:6.1f} s] controller connected: resuming\n", seconds);
        else fmt::print(o_.out, "[{:6.1f} s] controller disconnected: the puppet idles until one is connected\n", seconds);
        std::fflush(o_.out);
    }

    void print_status_line(const TickRecord& r, const vec3& root, float speed, double seconds) {
        const PipelineCounters& c = sh_.counters;
        fmt::print(o_.out,
                   "[{:6.1f} s] {:<8} {:4.2f} m/s  heading {:4.0f}°  at ({:6.2f}, {:6.2f})  walked {:5.1f} m | "
                   "tick max {:.0f} µs  input→tick max {:.1f} ms  frame max {:.0f} µs  frames {} (missed {})  "
                   "dropped {}{}\n",
                   seconds, connected_ ? activity(speed) : "idle", speed, r.heading * det::kRadToDeg, root.x, root.z,
                   result_.distance_m, c.tick_time_max_ns.load(std::memory_order_relaxed) / 1e3,
                   c.input_latency_max_ns.load(std::memory_order_relaxed) / 1e6,
                   c.frame_time_max_ns.load(std::memory_order_relaxed) / 1e3,
                   c.frames.load(std::memory_order_relaxed), c.missed_frames.load(std::memory_order_relaxed),
                   c.samples_dropped.load(std::memory_order_relaxed), connected_ ? "" : "  [no controller]");
        std::fflush(o_.out);
    }

    const PipelineOptions& o_;
    PipelineShared& sh_;
    const LiveTuning& tuning_;
    PipelineResult& result_;
    const int tick_rate_hz_;
    const std::uint32_t flush_ticks_;
    std::unique_ptr<RecordingSink> log_;  // ends itself cleanly on a full disk
    std::uint64_t last_hash_ = 0;               // the state after the newest tick logged
    std::uint64_t ticks_since_checkpoint_ = 0;  // ticks logged after the newest checkpoint
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> trace_{nullptr, &std::fclose};
    SimConfig logged_config_;  // the configuration the last change notice left in force
    vec3 previous_root_;
    bool connected_ = true;
    std::int64_t last_flush_;
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

// One run of the pipeline, in its phases: prepare (everything that allocates,
// in the constructor), start the threads, write until the simulation is done,
// shut down. Members are destroyed in reverse order, so the guard joins the
// threads before anything they use goes away.
class PipelineRun {
public:
    explicit PipelineRun(const PipelineOptions& o)
        : o_(o), shared_(std::make_unique<PipelineShared>()), sh_(*shared_),
          loop_(prepare_simulation(o, sh_)), writer_(o, loop_->simulation(), sh_, tuning_, result_),
          tuning_(prepare_live_tuning(o, loop_->simulation())) {
        if (o.realtime.lock_memory) note_realtime_failure(lock_all_memory());
    }

    void start() {
        // Only this thread takes SIGINT/SIGTERM: the workers start with them blocked.
        sigset_t stop_signals, previous_mask;
        sigemptyset(&stop_signals);
        sigaddset(&stop_signals, SIGINT);
        sigaddset(&stop_signals, SIGTERM);
        pthread_sigmask(SIG_BLOCK, &stop_signals, &previous_mask);
        try {
            start_threads();
        } catch (...) {
            pthread_sigmask(SIG_SETMASK, &previous_mask, nullptr);
            throw;
        }
        pthread_sigmask(SIG_SETMASK, &previous_mask, nullptr);
        apply_realtime_settings();
        notifier_.ready();  // systemd (Type=notify): the pipeline runs
    }

    // The writer: this thread drains the records into the log, the trace and the
    // status line, and watches for a stop, a closed window and config edits.
    void write_until_done() {
        TickRecord record;
        for (;;) {
            const bool finished = sh_.simulation_done.load(std::memory_order_acquire);
            // At most one ring's worth per pass: a --fast simulation refills the
            // ring as fast as it is drained, and an unbounded drain never got to
            // the config watcher below, so live edits applied late or never.
            std::size_t drained = 0;
            while (drained < kRecordRingCapacity && sh_.records.try_pop(record)) {
                writer_.handle(record);
                ++drained;
            }
            const bool emptied = drained < kRecordRingCapacity;
            const std::int64_t now = monotonic_ns();
            writer_.flush_by_clock(now);
            if (finished && emptied) break;  // simulation_done was read before the last drain
            if (stop_seen_ < 0 && o_.stop_request && o_.stop_request->load()) {
                stop_seen_ = now;
                result_.stopped = true;
                sh_.stop.store(true);
            }
            if (o_.device) publish_device_counters();
            if (!result_.display_closed && display_.closed.load(std::memory_order_acquire)) {
                result_.display_closed = true;  // closing the window ends the run normally
                sh_.stop.store(true);
            }
            notifier_.poll(now, sh_.counters.simulation_heartbeat.load(std::memory_order_relaxed),
                           sh_.counters.frames.load(std::memory_order_relaxed));
            const bool hurry = o_.virtual_time || sh_.stop.load(std::memory_order_relaxed);
            // Still behind: look at the watcher without waiting, then drain on.
            tuning_.wait_and_poll(sh_, o_.err, !emptied ? 0 : hurry ? kWriterPollShortMs : kWriterPollMs);
        }
    }

    PipelineResult shut_down() {
        notifier_.stopping();
        sh_.stop.store(true);
        if (o_.device) {
            device_->stop();
            publish_device_counters();  // its final counts, now that it has stopped
        }
        for (std::thread* t : guard_.threads)
            if (t->joinable()) t->join();
        TickRecord record;
        while (sh_.records.try_pop(record)) writer_.handle(record);
        writer_.close();
        collect_result(monotonic_ns());
        return result_;
    }

private:
    static std::unique_ptr<SimulationLoop> prepare_simulation(const PipelineOptions& o, PipelineShared& sh) {
        set_simulation_float_mode();
        auto loop = std::make_unique<SimulationLoop>(o.config, sh, o.scheduled_changes, o.virtual_time);
        if (o.graph) attach_motion_graph(loop->simulation_before_start(), o.graph);
        return loop;
    }

    static LiveTuning prepare_live_tuning(const PipelineOptions& o, const Simulation& sim) {
        LiveTuning tuning;
        tuning.published = o.config;
        tuning.realtime = o.realtime;
        tuning.ui = o.ui_base.ui;
        tuning.timing.interpolation = o.interpolation;
        tuning.simulation = &sim;
        if (!o.watch_config_file.empty()) tuning.watcher = std::make_unique<ConfigWatcher>(o.watch_config_file);
        return tuning;
    }

    void start_threads() {
        // The render thread first: the display must open before the clock starts.
        start_display();
        // The input thread before the simulation thread: a device backend that
        // cannot open its pad fails here, before any tick runs or is recorded.
        // The clock starts once it is open: a pad's start-up dialogue (up to
        // 200 ms for a Switch Pro's calibration) must not count as a late tick.
        if (o_.device) {
            if (const Outcome started = device_->start(sh_.input_ring, *o_.device); !started.ok())
                throw ImportError("--input " + o_.device->backend, 0, started.problem());
            result_.input_description = device_->backend_description();
        }
        wall_start_ = monotonic_ns();
        const std::int64_t t0 = o_.virtual_time ? 0 : wall_start_ + kThreadStartLeadNs;
        if (!o_.device) {
            in_thread_ = std::thread(input_thread, std::ref(sh_), std::cref(o_.script), t0, o_.virtual_time);
        }
        sim_thread_ = std::thread(simulation_thread, std::ref(sh_), std::ref(*loop_), o_.total_ticks, t0,
                                  o_.virtual_time, !o_.script.stamp_when_read, o_.test_stall_simulation_ms,
                                  std::ref(sim_result_));
    }

    void start_display() {
        const Simulation& sim = loop_->simulation();
        drawn_terrain_ = o_.config.terrain;  // copied here, on the writer's thread
        const RenderInputs inputs{&o_.display,       &sim.skeleton(),
                                  &drawn_terrain_,   o_.config.ankle_height,
                                  o_.config.tick_rate_hz, o_.interpolation,
                                  o_.test_render_stall_after_frames, o_.test_render_stall_ns,
                                  o_.ui ? &ui_options_ : nullptr, &o_.config};
        gfx_thread_ = std::thread(render_thread, std::ref(sh_), o_.frame_rate_hz, o_.virtual_time, inputs,
                                  std::ref(display_), std::ref(result_.frame_time), std::ref(result_.present_latency));
        while (display_.state.load(std::memory_order_acquire) == DisplayThreadState::opening)
            sleep_until_ns(monotonic_ns() + kDisplayOpenPollNs);
        if (display_.state.load(std::memory_order_acquire) == DisplayThreadState::failed) {
            gfx_thread_.join();
            throw render::PlatformError(display_.error);
        }
        result_.display_description = display_.description;
    }

    // [realtime]: priorities and CPUs, once the threads run. Virtual time waits
    // by spinning: never under SCHED_FIFO, where a spinning thread would starve
    // the writer it waits for.
    void apply_realtime_settings() {
        const RealtimeConfig& rt = o_.realtime;
        const bool fifo = !o_.virtual_time;
        note_realtime_failure(apply_thread_settings(o_.device ? device_->thread() : in_thread_, "mario-input",
                                                    fifo ? rt.input_priority : 0, rt.input_cpu));
        note_realtime_failure(apply_thread_settings(sim_thread_, "mario-sim", fifo ? rt.simulation_priority : 0,
                                                    rt.simulation_cpu));
        note_realtime_failure(apply_thread_settings(gfx_thread_, "mario-render", fifo ? rt.render_priority : 0,
                                                    rt.render_cpu));
        if (!result_.realtime_warning.empty())
            log_message(LogLevel::warning, fmt::format("warning: real-time settings not permitted ({}); running with normal scheduling",
                       result_.realtime_warning), o_.err);
    }

    void note_realtime_failure(const Outcome& applied) {
        if (applied.ok()) return;
        result_.realtime_warning += (result_.realtime_warning.empty() ? "" : "; ") + applied.problem();
    }

    // The backend keeps its own counters; the status line reads these.
    void publish_device_counters() {
        const input::InputThreadStats st = device_->stats();
        sh_.counters.samples_pushed.store(st.samples, std::memory_order_relaxed);
        sh_.counters.samples_dropped.store(st.ring_dropped, std::memory_order_relaxed);
    }

    void collect_result(std::int64_t end) {
        PipelineResult& r = result_;
        if (r.stopped) {
            std::int64_t from = stop_seen_;
            if (o_.stop_request_time_ns && o_.stop_request_time_ns->load() > 0) from = o_.stop_request_time_ns->load();
            r.shutdown_ms = static_cast<double>(end - from) / 1e6;
        }
        r.wall_s = static_cast<double>(end - wall_start_) / 1e9;
        r.final_state = loop_->simulation().state();
        r.ticks = r.final_state.tick;
        r.final_hash = hash_state(r.final_state);
        r.input_latency = loop_->input_latency();
        r.tick_time = sim_result_.tick_time;
        r.interpolation = o_.interpolation;
        r.samples_pushed = sh_.counters.samples_pushed.load();
        r.samples_dropped = sh_.counters.samples_dropped.load();
        r.frames = sh_.counters.frames.load();
        r.missed_frames = sh_.counters.missed_frames.load();
        r.catch_up_drops = sim_result_.catch_up_drops;
        r.catch_up_skipped_s = static_cast<double>(sim_result_.skipped_ns) / 1e9;
        r.max_ticks_per_wake = sim_result_.max_ticks_per_wake;
        r.records_dropped = sh_.counters.records_dropped.load();
        r.config_changes = loop_->config_changes();
        r.disconnects = loop_->assembler().disconnects();
        r.reconnects = loop_->assembler().reconnects();
        r.watchdog_pings = notifier_.pings_sent();
        r.watchdog_withheld = notifier_.pings_withheld();
    }

    const PipelineOptions& o_;
    PipelineResult result_;
    std::unique_ptr<PipelineShared> shared_;
    PipelineShared& sh_;
    std::unique_ptr<SimulationLoop> loop_;
    RecordWriter writer_;  // before tuning_, as the run made its outputs before watching the file
    LiveTuning tuning_;
    SimulationThreadResult sim_result_;
    DisplayThreadState display_;
    ui::TuningUiOptions ui_options_{o_.ui_base, o_.ui_config_file, "", o_.out};
    Terrain drawn_terrain_;  // the render thread's (RenderInputs::terrain)
    std::thread sim_thread_, in_thread_, gfx_thread_;
    std::unique_ptr<input::InputThread> device_ = std::make_unique<input::InputThread>();  // stopped (joined) by its destructor
    ThreadGuard guard_{{&sim_thread_, &in_thread_, &gfx_thread_}, sh_};
    std::int64_t wall_start_ = 0;
    std::int64_t stop_seen_ = -1;  // when the writer saw the stop request
    ServiceNotifier notifier_;     // systemd's READY=1 and WATCHDOG=1
};

}  // namespace

// ---------------------------------------------------------------- the run

PipelineResult run_pipeline(const PipelineOptions& o) {
    PipelineRun run(o);
    run.start();
    run.write_until_done();
    return run.shut_down();
}

}  // namespace marionette
