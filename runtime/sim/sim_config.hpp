#pragma once
// Every tunable the simulation reads, as plain data, one struct per subsystem:
// each job and each part of the tick is handed only its own part (the gait a
// GaitConfig, the ground a TerrainConfig, ...). SimConfig is their sum, so the
// schema and the logs treat it as one flat set of keys. Loading, validation and
// the documentation of each key live with the TOML schema (app/config/config.cpp,
// docs/config.md); the defaults here are the ones config/marionette.toml states.
#include <array>
#include <cstdint>
#include <string>

#include "runtime/gait/gait_config.hpp"
#include "runtime/ground/terrain.hpp"
#include "runtime/sim/tick_input.hpp"

namespace marionette {

// [motion] source: what poses the puppet. `automatic` is the motion graph when one
// is attached (`--graph`), the gait otherwise.
enum class MotionSourceSetting : std::int32_t { automatic = 0, gait = 1, graph = 2, graph_feet = 3, matching = 4 };
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

// [simulation]
struct TickConfig {
    std::int32_t tick_rate_hz = 240;
    std::int32_t max_catch_up_ticks = 8;   // real-time driver: ticks run per wake-up at most

};

// [terrain]
struct TerrainConfig {
    // [terrain] the ground walked on: `name` is where it came from (a built-in
    // name or a file path, resolved by app/); the data travel inline in every
    // effective configuration, so a log fully determines its ground. Built-in
    // default: flat (the shipped config/marionette.toml names stairs).
    std::string terrain_name = "flat";
    Terrain terrain;
};

// [motion]
struct MotionSourceConfig {
    // [motion] which source poses the puppet, and how a change of source blends
    // (docs/motion-graph.md, "Motion sources")
    MotionSourceSetting motion_source = MotionSourceSetting::automatic;
    float motion_crossfade_s = 0.4f;              // a live change of source cross-fades over this long
    float feet_release_s = 0.15f;                 // graph_feet: a lifted foot eases from its pin back to the clip
    float feet_terrain_rate = 10.0f;              // graph_feet: 1/s the body follows the ground height
};

// [motion_graph]: the run-time keys (turned into a GraphControllerConfig when a
// graph is attached) and the button map.
struct MotionGraphConfig {
    // [motion_graph] the run-time controller (runtime/graph/graph_controller.hpp)
    float graph_horizon_s = 1.0f;                 // look-ahead of the stick-following search
    std::int32_t graph_max_nodes_per_tick = 64;   // search nodes expanded per tick at most
    float graph_full_stick_speed = 1.5f;          // leg lengths per second at full stick
    float graph_leg_metres = 0.9f;                // the graph's leg is scaled to this many metres
    float graph_attract_after_s = 30.0f;          // seconds without input before the attract-mode walk
    float graph_attract_temperature = 1.0f;       // attract walk: edge weight 1 / (1 + cost / temperature)
    std::int32_t graph_attract_seed = 1;          // attract-mode PRNG seed
    float graph_transition_weight = 1.0f;         // path cost: seconds per unit of transition distance
    // [motion_graph.buttons] button bit → label (runtime/sim/tick_input.hpp kButtonNames order)
    std::array<GraphButtonBinding, kButtonCount> graph_buttons = default_graph_buttons();
};

// [motion_matching]: the motion-matching source (runtime/matching/, docs/motion-matching.md).
struct MotionMatchingConfig {
    // feature weights (each group normalised by its own standard deviation first)
    float matching_foot_position_weight = 0.75f;
    float matching_foot_velocity_weight = 1.0f;
    float matching_hips_velocity_weight = 1.0f;
    float matching_trajectory_position_weight = 1.0f;
    float matching_trajectory_facing_weight = 1.5f;
    // the controller
    float matching_search_interval_s = 0.1f;
    float matching_search_threshold_m = 0.15f;
    float matching_inertialization_s = 0.25f;
    float matching_velocity_halflife_s = 0.12f;
    float matching_facing_halflife_s = 0.15f;
    float matching_correction_halflife_s = 0.08f;
};

// Thread settings and graph build parameters are no part of it: the tick never
// reads them (app/config/app_config.hpp holds them beside a SimConfig).
struct SimConfig : TickConfig, GaitConfig, TerrainConfig, MotionSourceConfig, MotionGraphConfig, MotionMatchingConfig {};

}  // namespace marionette
