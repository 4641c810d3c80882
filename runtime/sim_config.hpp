#pragma once
// Every tunable the simulation reads, as plain data. Loading, validation and the
// documentation of each key live with the TOML schema (app/config.cpp,
// docs/config.md); the defaults here are the ones config/marionette.toml states.
#include <array>
#include <cstdint>
#include <string>

#include "runtime/gait_prototype.hpp"
#include "runtime/terrain.hpp"
#include "runtime/tick_input.hpp"

namespace marionette {

// [motion_graph.buttons]: the graph label a button plays on press ("" for none),
// and where the value came from, for the error when the graph lacks the label.
struct GraphButtonBinding {
    std::string label;
    std::string file;           // configuration file that set it last
    std::int32_t line = 0;      // 0: the built-in default
};
// Today's mapping: the face buttons play the default graph's actions.
inline std::array<GraphButtonBinding, kButtonCount> default_graph_buttons() {
    std::array<GraphButtonBinding, kButtonCount> b{};
    b[static_cast<std::size_t>(Button::south)].label = "jump";
    b[static_cast<std::size_t>(Button::east)].label = "wave";
    b[static_cast<std::size_t>(Button::west)].label = "bow";
    b[static_cast<std::size_t>(Button::north)].label = "look_around";
    return b;
}

// [motion] source: what poses the puppet. `automatic` is the motion graph when one
// is attached (`--graph`), the gait otherwise.
enum class MotionSourceSetting : std::int32_t { automatic = 0, gait = 1, graph = 2, graph_feet = 3 };

struct SimConfig {
    // [simulation]
    std::int32_t tick_rate_hz = 240;
    std::int32_t max_catch_up_ticks = 8;   // real-time driver: ticks run per wake-up at most

    // [puppet] proportions in metres
    float pelvis_height = 0.95f;           // hip joint height above the ground when standing
    float hip_width = 0.18f;
    float thigh_length = 0.44f;
    float shin_length = 0.43f;
    float ankle_height = 0.08f;
    float foot_length = 0.14f;
    float toe_length = 0.06f;
    float spine_length = 0.50f;            // pelvis to neck, split over three spine joints
    float neck_length = 0.10f;
    float head_length = 0.22f;
    float shoulder_width = 0.36f;
    float upper_arm_length = 0.29f;
    float forearm_length = 0.26f;
    float hand_length = 0.18f;

    // [locomotion]
    float max_speed = 3.0f;                // m/s at full stick deflection
    float walk_cycle_speed = 1.4f;         // speed the generated walk clip plays at 1×
    float stride_length = 1.4f;            // metres per full walk cycle at walk_cycle_speed
    float acceleration = 6.0f;             // m/s² toward the commanded velocity
    float turn_rate_deg_s = 360.0f;        // heading follows the movement direction
    float stick_deadzone = 0.12f;          // radial, fraction of full deflection
    float response_curve = 0.5f;           // 0 linear … 1 quadratic: f(d) = (1−c)·d + c·d²

    // [gait] the spline-IK gait (docs/gait.md)
    float gait_pelvis_height = 0.84f;      // hip height above the mean foot ground while stepping
    float step_length_multiplier = 0.45f;  // step length = multiplier · sqrt(speed)
    float min_step_duration = 0.26f;       // s, fastest cadence
    float max_step_duration = 0.6f;        // s, slowest cadence (slow walk, turning in place)
    float walk_duty = 0.58f;               // fraction of a cycle each foot is down when walking (> 0.5)
    float run_duty = 0.36f;                // … when running (< 0.5: flight phase)
    float run_threshold = 1.9f;            // m/s: above it the gait runs
    float swing_clearance = 0.03f;         // m the swing sole keeps above the ground between its ends
    float spine_lean_deg_per_m_s = 4.0f;   // forward lean per unit speed
    float max_spine_lean_deg = 10.0f;
    float interpolation_rate = 8.0f;       // 1/s: lean, walk/run blend and pelvis height approach their targets
    float slope_speed_factor = 0.01f;      // speed reduction per degree of slope along the heading
    float turn_in_place_deg = 120.0f;      // reversals wider than this turn in place
    float stop_transition_s = 0.3f;        // the swing foot's time to plant after a stop, at most
    float breath_amplitude = 0.005f;       // m of pelvis rise when idle
    float breath_period_s = 4.0f;
    GaitPrototypes walk = default_walk_prototypes();   // [gait.walk]
    GaitPrototypes run = default_run_prototypes();     // [gait.run]

    // [terrain] the ground walked on: `name` is where it came from (a built-in
    // name or a file path, resolved by app/); the data travel inline in every
    // effective configuration, so a log fully determines its ground. Built-in
    // default: flat (the shipped config/marionette.toml names stairs).
    std::string terrain_name = "flat";
    Terrain terrain;
    // [realtime] `marionette run` thread settings (app/realtime.cpp); never read by
    // the tick. Priority 0 = normal scheduling, 1–99 = SCHED_FIFO; cpu −1 = any.
    std::int32_t input_priority = 0;
    std::int32_t simulation_priority = 0;
    std::int32_t render_priority = 0;
    std::int32_t input_cpu = -1;
    std::int32_t simulation_cpu = -1;
    std::int32_t render_cpu = -1;
    std::int32_t lock_memory = 0;          // 1: mlockall(MCL_CURRENT | MCL_FUTURE) before the threads start
    // [motion_graph] build parameters and path costs (docs/motion-graph.md)
    std::int32_t graph_analysis_rate_hz = 30;     // clips are resampled to this rate for the build
    std::int32_t graph_window_frames = 10;        // k: distance window and transition length
    std::int32_t graph_neighbourhood_frames = 4;  // local minima over (2h+1)² pairs
    float graph_threshold_percentile = 5.0f;      // threshold as a percentile of all distances
    float graph_threshold_absolute = 0.0f;        // > 0: absolute threshold (leg lengths²) instead
    float graph_bridge_percentile = 90.0f;        // looser percentile for bridges into cut-off clips
    float graph_contact_height = 0.08f;           // foot contact: height above ground, leg lengths
    float graph_contact_speed = 0.6f;             // foot contact: speed, leg lengths per second
    float graph_transition_weight = 1.0f;         // path cost: seconds per unit of transition distance
    // [motion_graph] the run-time controller (runtime/graph_controller.hpp)
    float graph_horizon_s = 1.0f;                 // look-ahead of the stick-following search
    std::int32_t graph_max_nodes_per_tick = 64;   // search nodes expanded per tick at most
    float graph_full_stick_speed = 1.5f;          // leg lengths per second at full stick
    float graph_leg_metres = 0.9f;                // the graph's leg is scaled to this many metres
    float graph_attract_after_s = 30.0f;          // seconds without input before the attract-mode walk
    float graph_attract_temperature = 1.0f;       // attract walk: edge weight 1 / (1 + cost / temperature)
    std::int32_t graph_attract_seed = 1;          // attract-mode PRNG seed
    // [motion_graph.buttons] button bit → label (runtime/tick_input.hpp kButtonNames order)
    std::array<GraphButtonBinding, kButtonCount> graph_buttons = default_graph_buttons();
    // [motion] which source poses the puppet, and how a change of source blends
    // (docs/motion-graph.md, "Motion sources")
    MotionSourceSetting motion_source = MotionSourceSetting::automatic;
    float motion_crossfade_s = 0.4f;              // a live change of source cross-fades over this long
    float feet_release_s = 0.15f;                 // graph_feet: a lifted foot eases from its pin back to the clip
    float feet_terrain_rate = 10.0f;              // graph_feet: 1/s the body follows the ground height
};

}  // namespace marionette
