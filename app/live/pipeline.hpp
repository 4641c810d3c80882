#pragma once
// The live pipeline (../shared/DESIGN.md, docs/pipeline.md):
//
//   input thread ──TimedInput──▶ SPSC ring ──▶ simulation thread ──TickRecord──▶ SPSC ring ──▶ writer (main thread)
//                                                   │                                       log, trace, status, config
//                                                   └──StateFrame──▶ triple buffer ──▶ render thread
//
// plus a configuration handoff (triple buffer) from the writer's file watcher
// to the simulation. Every queue is single-producer/single-consumer with a fixed
// capacity. Each thread's steady-state work is a plain method (SimulationLoop,
// FrameLoop, InputRingWriter) that the zero-allocation test drives directly.
#include <array>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "app/config/app_config.hpp"
#include "app/live/recording.hpp"
#include "app/ui/pad_presses.hpp"
#include "render_es/mesh.hpp"
#include "render_es/platform.hpp"
#include "render_es/settings.hpp"
#include "runtime/formats/input_log.hpp"
#include "runtime/handoff/latency_histogram.hpp"
#include "runtime/handoff/latest_value.hpp"
#include "runtime/graph/motion_graph.hpp"
#include "runtime/sim/simulation.hpp"
#include "runtime/handoff/spsc_ring.hpp"
#include "runtime/formats/stick_program.hpp"
#include "runtime/handoff/tick_input_assembler.hpp"

namespace marionette {

inline constexpr std::size_t kInputRingCapacity = 4096;    // 4 s of samples at 1 kHz
inline constexpr std::size_t kRecordRingCapacity = 16384;  // 68 s of ticks at 240 Hz
inline constexpr int kSimulatedControllerHz = 1000;

using InputRing = SpscRing<TimedInput, kInputRingCapacity>;

// The input that reached one tick: how many samples it consumed, the stamps of
// the oldest and newest of them, and when it ran. A frame names, through these,
// the samples it is the first to show (FrameLoop::presented).
struct TickInputStamps {
    std::uint64_t tick = 0;     // the state's tick number after the step (0: no tick yet)
    std::uint32_t samples = 0;  // 0: none consumed (the stamps are unset)
    std::int64_t oldest_ns = 0;
    std::int64_t newest_ns = 0;
    std::int64_t ran_ns = 0;    // when the tick ran
};
// The newest ticks' entries, by tick % size: 133 ms at 240 Hz, far more than the
// ticks between two frames (a frame that comes later than that counts the rest).
inline constexpr std::size_t kTickStampHistory = 32;
using TickStampHistory = std::array<TickInputStamps, kTickStampHistory>;

// What the render thread interpolates between: the two latest ticks.
struct StateFrame {
    PuppetState previous;
    PuppetState current;
    std::int64_t current_time_ns = 0;  // when `current`'s tick was due
    std::int64_t tick_ns = 0;
    bool connected = true;             // the controller, for the on-screen notice
    TickStampHistory recent_inputs{};  // the input that reached `current` and the ticks before it
    // The tuning UI's pad (docs/ui.md): the newest tick's input as the pad gave
    // it (before the UI, when open, took it from the puppet).
    TickInput pad{};
};

// Simulation → writer, per tick (and per configuration change, in order).
struct TickRecord {
    enum class Kind : std::uint8_t { tick, config_change };
    Kind kind = Kind::tick;
    bool connected = true;        // the controller, as this tick saw it
    std::uint64_t tick = 0;       // ticks completed after this one
    std::uint64_t hash = 0;
    TickInput input{};
    // Plain floats: ring items must be trivially copyable, which GLM vectors are not.
    std::array<float, 3> root_position{};
    std::array<float, 2> velocity{};
    float heading = 0.0f;
    // config_change: which configuration is now in force. The configuration itself
    // (it owns the terrain's arrays) stays with the writer, who made or read it:
    // a live edit by its version, a recorded change by its index.
    enum class ConfigSource : std::uint8_t { live_edit, recorded };
    ConfigSource config_source = ConfigSource::live_edit;
    std::uint32_t config_id = 0;
};
using RecordRing = SpscRing<TickRecord, kRecordRingCapacity>;

// A validated configuration for the simulation to apply at its next tick boundary.
struct ConfigUpdate {
    std::uint32_t version = 0;
    SimConfig config{};
};

// A configuration the tuning UI made (render thread → writer), offered to the
// simulation as a live edit of the file would be.
struct UiEdit {
    AppConfig config;
};

// A change recorded in an input log, applied before tick `before_tick` (0-based).
struct ScheduledConfigChange {
    std::uint64_t before_tick = 0;
    SimConfig config{};
};

// Written by one thread each, read (relaxed) by the status line.
struct PipelineCounters {
    std::atomic<std::uint64_t> samples_pushed{0};
    std::atomic<std::uint64_t> samples_dropped{0};
    std::atomic<std::uint64_t> frames{0};
    std::atomic<std::uint64_t> missed_frames{0};
    std::atomic<std::uint64_t> catch_up_drops{0};
    std::atomic<std::uint64_t> records_dropped{0};
    // Bumped by the simulation thread at every tick: with `frames` (the render
    // loop's), what the systemd watchdog looks at (app/live/service_notify.hpp).
    std::atomic<std::uint64_t> simulation_heartbeat{0};
    // Maxima over the last second, published once a second by their thread.
    std::atomic<std::int64_t> tick_time_max_ns{0};
    std::atomic<std::int64_t> input_latency_max_ns{0};
    std::atomic<std::int64_t> frame_time_max_ns{0};
};

// Everything the threads share. Allocated once, before the threads start.
struct PipelineShared {
    InputRing input_ring;
    RecordRing records;
    LatestValue<StateFrame> states;
    LatestValue<ConfigUpdate> config_updates;
    // The tuning UI (docs/ui.md). While it is open the simulation gets the pad
    // at rest (the recorded input is that rest, so replay needs no UI); its
    // edits go to the writer, and every configuration the writer hands over
    // comes back to it, so a file edit and a panel edit never undo each other.
    std::atomic<bool> ui_captures_input{false};
    // …except the sticks while the spline editor's d-pad mode is on: the puppet
    // keeps walking (the left stick) while the d-pad steps a key; recorded as given.
    std::atomic<bool> ui_passes_sticks{false};
    ui::PadEventRing pad_events;       // presses with their ticks, in order (ui::press_event)
    LatestValue<UiEdit> ui_edits;
    LatestValue<SimConfig> accepted_configs;
    // The terrain the simulation walks on after a terrain edit it applied
    // (writer → render thread, which rebuilds its ground mesh from it).
    LatestValue<Terrain> applied_terrain;
    // Virtual time only: the newest timestamp the input thread has pushed.
    std::atomic<std::int64_t> input_watermark_ns{INT64_MIN};
    std::atomic<bool> input_done{false};
    std::atomic<bool> simulation_done{false};
    std::atomic<bool> stop{false};
    PipelineCounters counters;
};

// The simulation thread's work for one tick: apply a pending configuration,
// drain the samples due, step, publish the state pair, hand a record to the
// writer. No allocation, no lock, no system call.
class SimulationLoop {
public:
    // `wait_when_full`: virtual time (nothing is real-time, so wait for the writer
    // instead of dropping a record). `scheduled`: changes replayed from a log.
    SimulationLoop(const SimConfig& config, PipelineShared& shared, std::vector<ScheduledConfigChange> scheduled = {},
                   bool wait_when_full = false);
    void run_tick(std::int64_t tick_time_ns, std::int64_t now_ns);

    const Simulation& simulation() const { return sim_; }
    // Before the first tick only (Simulation::use_motion_graph).
    Simulation& simulation_before_start() { return sim_; }
    const TickInputAssembler& assembler() const { return assembler_; }
    const InputLatencyHistogram& input_latency() const { return latency_; }
    std::uint64_t config_changes() const { return config_changes_; }

private:
    void apply(const SimConfig& config, TickRecord::ConfigSource source, std::uint32_t id);
    void push(const TickRecord& record);

    Simulation sim_;
    PipelineShared& shared_;
    std::vector<ScheduledConfigChange> scheduled_;
    size_t next_scheduled_ = 0;
    bool wait_when_full_ = false;
    TickInputAssembler assembler_;
    InputLatencyHistogram latency_;
    std::int64_t latency_window_max_ns_ = 0;
    std::uint64_t config_changes_ = 0;
    TickStampHistory input_stamps_{};  // copied into every published state pair
    std::uint32_t previous_buttons_ = 0;
    TickRecord record_{};  // reused, so the tick builds no large temporaries
};

// Sample stamp → the frame that first showed it was presented: 10 µs buckets up to 100 ms.
using PresentLatencyHistogram = DurationHistogram<10'000, 10'000>;

// End-to-end latency, per frame that showed new input: from the oldest and the
// newest sample that reached it (through the ticks it is the first to show) to
// its presentation, and from the newest tick it shows having run to then.
struct PresentLatency {
    PresentLatencyHistogram oldest;
    PresentLatencyHistogram newest;
    PresentLatencyHistogram tick_to_present;
};

// The render thread's work for one frame: take the newest state pair and pose
// the puppet from it, by [timing] interpolation (app_config.hpp). With s = (frame
// time − the current tick's time) / dt, clamped to [0, 1]:
//   interpolate — alpha = s between the previous and the current state: one tick
//                 behind, never extrapolating; a tick is shown in full once s = 1;
//   extrapolate — alpha = 1 + s: the current state carried on along the last
//                 tick's motion, at most one tick ahead;
//   latest      — alpha = 1: the current state as it is.
// Then presented() stamps the frame. (The GLES renderer draws from the pair with
// render::interpolate_state / extrapolate_state.)
class FrameLoop {
public:
    explicit FrameLoop(PipelineShared& shared, Interpolation mode = Interpolation::interpolate)
        : shared_(shared), mode_(mode) {}
    // Returns the posed root position.
    vec3 run_frame(std::int64_t frame_time_ns);
    // The frame run_frame() posed was presented (shown, or ready, headless) at
    // `present_ns`: adds its latencies when it shows ticks no frame showed before.
    void presented(std::int64_t present_ns);
    bool has_state() const { return has_state_; }
    double alpha() const { return alpha_; }  // 0 … 2 (above 1: extrapolated)
    // The newest tick the last frame shows in full.
    std::uint64_t shown_tick() const { return shown_tick_; }
    // The state pair the last run_frame() posed (valid once has_state()).
    const StateFrame& state_pair() const { return shared_.states.front(); }
    const std::array<vec3, kMaxJoints>& joints() const { return joints_; }
    const PresentLatency& present_latency() const { return present_; }

private:
    PipelineShared& shared_;
    Interpolation mode_;
    bool has_state_ = false;
    double alpha_ = 0.0;
    std::uint64_t shown_tick_ = 0;
    std::uint64_t last_presented_tick_ = 0;  // the newest tick an earlier frame showed
    std::array<vec3, kMaxJoints> joints_{};
    PresentLatency present_;
};

// Where the input thread's samples come from, prepared before it starts:
// events with timestamps relative to the start of the run.
struct InputScript {
    std::vector<TimedInput> events;  // non-decreasing timestamps
    // True: a live controller, stamped with the clock when read (the script's
    // time is when to read it). False: a recording, which keeps its stamps.
    bool stamp_when_read = true;
};

// The controller is unplugged at `at_s` for `for_s` seconds (hot-plug tests).
struct UnplugWindow {
    double at_s = 0.0;
    double for_s = 0.0;
};

// A stick program as a controller polled at `sample_rate_hz`, then left at rest
// when the program ends; during an unplug window it sends nothing but the
// disconnect marker.
InputScript script_from_program(const StickProgram& program, int sample_rate_hz,
                                const std::vector<UnplugWindow>& unplugged = {});
// A recorded log played live: tick k's input is stamped just after tick k−1's
// time, so tick k consumes exactly it.
InputScript script_from_log(const DecodedInputLog& log, std::int64_t tick_ns);

using TickTimeHistogram = DurationHistogram<1'000, 2048>;     // 1 µs buckets, ≤ 2 ms
using FrameTimeHistogram = DurationHistogram<1'000, 4096>;    // 1 µs buckets, ≤ 4 ms

// What the render thread draws on. Without `gl` it runs the headless frame loop
// (interpolation only, no GPU); with it, render_es draws every frame in a
// window or on KMS (render_es/view.hpp), presenting paced by the display.
struct DisplayOptions {
    bool gl = false;
    render::PlatformOptions platform;
    render::RenderSettings settings;
    // `[render] character` loaded (app/config/character_config.hpp); null: capsules.
    std::shared_ptr<const render::SkinnedMesh> body;
};

namespace input {
struct InputThreadOptions;
}

struct PipelineOptions {
    SimConfig config;
    RealtimeConfig realtime;           // thread settings, applied at start only
    InputScript script;
    // A real controller (input/input_thread.hpp) instead of the script: its own
    // thread pushes into the input ring; the run lasts until stopped.
    const input::InputThreadOptions* device = nullptr;
    std::vector<ScheduledConfigChange> scheduled_changes;
    std::uint64_t total_ticks = 0;
    std::shared_ptr<const MotionGraph> graph;  // drive the puppet from this graph (null: the gait)
    std::string graph_argument;        // --graph as given: the log names the graph by it
    // No clock: ticks run as fast as the input thread provides samples, each tick
    // waiting for every sample up to its time, so the run is deterministic.
    bool virtual_time = false;
    int frame_rate_hz = 60;            // the headless frame loop's pace
    Interpolation interpolation = Interpolation::interpolate;  // [timing]: what the render thread draws
    DisplayOptions display;
    // The tuning UI over the display (docs/ui.md): off when [ui] enabled = false.
    bool ui = false;
    AppConfig ui_base;                 // the run's whole configuration
    std::string ui_config_file;        // the file it came from ("" = defaults): Save writes there
    std::string record_file;           // input log ("" = none): its first file (app/live/recording.hpp)
    std::string record_rotate_dir;     // --record auto: keep the [recording] limits by deleting the oldest here
    RecordingLimits record_limits;
    std::string trace_file;            // per-tick CSV ("" = none)
    std::string watch_config_file;     // live tuning ("" = none)
    bool status_lines = true;          // once per simulated second
    std::FILE* out = stdout;           // status lines and notices
    std::FILE* err = stderr;           // configuration errors and warnings
    // Test hook (MARIONETTE_TEST_STALL_SIM_MS, docs/deploy.md): the simulation
    // thread sleeps this long after its first simulated second, as if stuck.
    std::int64_t test_stall_simulation_ms = 0;
    // Set (by a signal handler) to ask for a clean stop; the time it was set, if known.
    const std::atomic<bool>* stop_request = nullptr;
    const std::atomic<std::int64_t>* stop_request_time_ns = nullptr;
    // Test hook (fault injection, tests/app/test_faults.cpp): once this many frames
    // have been built, the render thread stalls for test_render_stall_ns inside
    // the next frame, as a blocked GPU driver would. 0 ns: off.
    std::uint64_t test_render_stall_after_frames = 0;
    std::int64_t test_render_stall_ns = 0;
};

struct PipelineResult {
    std::uint64_t ticks = 0;
    std::uint64_t final_hash = 0;
    PuppetState final_state{};
    double distance_m = 0.0;
    float top_speed = 0.0f;
    bool stopped = false;              // by stop_request, before the end
    double shutdown_ms = 0.0;          // stop request → threads joined and files closed
    double wall_s = 0.0;
    InputLatencyHistogram input_latency;
    TickTimeHistogram tick_time;
    FrameTimeHistogram frame_time;
    PresentLatency present_latency;
    Interpolation interpolation = Interpolation::interpolate;  // what the frames showed
    std::uint64_t samples_pushed = 0;
    std::uint64_t samples_dropped = 0;
    std::uint64_t frames = 0;
    std::uint64_t missed_frames = 0;
    std::uint64_t catch_up_drops = 0;
    double catch_up_skipped_s = 0.0;    // simulated time skipped by those drops
    std::int32_t max_ticks_per_wake = 0;  // most ticks run for one wake-up (≤ max_catch_up_ticks)
    std::uint64_t records_dropped = 0;  // > 0: the log and trace are incomplete
    std::uint64_t config_changes = 0;
    std::uint64_t disconnects = 0;
    std::uint64_t reconnects = 0;
    std::string realtime_warning;       // what the [realtime] settings could not do
    bool display_closed = false;        // the window was closed (ends the run)
    std::string display_description;    // the GL platform, when one was used
    std::string input_description;      // the device backend, when one was used
    std::string recording_stopped;      // why the recording ended early ("" = it did not)
    std::vector<std::string> record_files;  // the recording's files, first to last
    std::uint64_t watchdog_pings = 0;       // WATCHDOG=1 sent to systemd
    std::uint64_t watchdog_withheld = 0;    // intervals in which a loop made no progress
};

// Runs the whole pipeline until total_ticks have run, a stop is requested or the
// window is closed. Throws std::runtime_error when an output cannot be created
// or written, render::PlatformError when the display cannot be opened.
PipelineResult run_pipeline(const PipelineOptions& options);

}  // namespace marionette
