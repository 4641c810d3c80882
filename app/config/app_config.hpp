#pragma once
// What `marionette` reads from a configuration file: the simulation's part
// (SimConfig, runtime/sim/sim_config.hpp: every key the tick reads, and all an
// input log embeds) plus parts the tick never reads: the live pipeline's
// thread settings ([realtime]) and render timing ([timing]), and the offline
// graph build's parameters (the [motion_graph] build keys). Loading, validation and the documentation of each
// key live with the TOML schema (app/config/config.cpp, docs/config.md); the
// defaults here are the ones config/marionette.toml states.
#include <cstdint>

#include "runtime/sim/sim_config.hpp"

namespace marionette {

// [realtime]: `marionette run` thread settings (app/live/realtime.cpp), applied
// at start only. Priority 0 = normal scheduling, 1–99 = SCHED_FIFO; cpu −1 = any.
struct RealtimeConfig {
    std::int32_t input_priority = 0;
    std::int32_t simulation_priority = 0;
    std::int32_t render_priority = 0;
    std::int32_t input_cpu = -1;
    std::int32_t simulation_cpu = -1;
    std::int32_t render_cpu = -1;
    std::int32_t lock_memory = 0;          // 1: mlockall(MCL_CURRENT | MCL_FUTURE) before the threads start

    bool operator==(const RealtimeConfig&) const = default;
};

// [recording]: where `run --record auto` keeps its logs and how much room they
// may take (docs/config.md, app/live/recording.hpp). Read at start only, not in logs.
struct RecordingConfig {
    float max_total_mb = 1024.0f;  // all recordings in the directory; the oldest are deleted first
    float max_file_mb = 64.0f;     // a recording continues in NAME.1, NAME.2, ... past this
    float min_free_mb = 64.0f;     // recording stops rather than leave less free on the file system

    bool operator==(const RecordingConfig&) const = default;
};

// [motion_graph] build parameters (docs/motion-graph.md), read by graph builds
// only: `graph build`, the default graph and the stale-graph rebuild.
struct GraphBuildConfig {
    std::int32_t graph_analysis_rate_hz = 30;     // clips are resampled to this rate for the build
    std::int32_t graph_window_frames = 10;        // k: distance window and transition length
    std::int32_t graph_neighbourhood_frames = 4;  // local minima over (2h+1)² pairs
    float graph_threshold_percentile = 5.0f;      // threshold as a percentile of all distances
    float graph_threshold_absolute = 0.0f;        // > 0: absolute threshold (leg lengths²) instead
    float graph_bridge_percentile = 90.0f;        // looser percentile for bridges into cut-off clips
    float graph_contact_height = 0.08f;           // foot contact: height above ground, leg lengths
    float graph_contact_speed = 0.6f;             // foot contact: speed, leg lengths per second

    bool operator==(const GraphBuildConfig&) const = default;
};

// [timing]: what the render thread draws (app/live/pipeline.hpp, FrameLoop),
// applied at start only. Never read by the simulation, never in logs: the three
// choices give the same ticks, hashes and recordings.
enum class Interpolation : std::uint8_t {
    interpolate,  // one tick behind, between the two newest ticks (no extrapolation)
    extrapolate,  // the newest tick, carried forward by the time since it was due (at most one tick)
    latest,       // the newest tick as it is, without delay
};

struct TimingConfig {
    Interpolation interpolation = Interpolation::interpolate;

    bool operator==(const TimingConfig&) const = default;
};

// [ui]: the in-app tuning UI (app/ui/, docs/ui.md), read at start only, never
// in logs. enabled = false locks it (a kiosk in service mode).
struct UiConfig {
    bool enabled = true;
    bool operator==(const UiConfig&) const = default;
};

struct AppConfig {
    SimConfig sim;                 // what the tick reads; logs embed exactly this
    RealtimeConfig realtime;
    GraphBuildConfig graph_build;
    RecordingConfig recording;
    TimingConfig timing;
    UiConfig ui;
};

}  // namespace marionette
