#include "app/config/config.hpp"

#include <sys/stat.h>
#include <toml++/toml.h>
#include <cerrno>
#include <cstring>
#include <iterator>

#include <charconv>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <type_traits>
#include <variant>

#include "app/config/embedded.hpp"
#include "app/config/terrain_file.hpp"

namespace marionette {

namespace {

// A key's field: a member of one of AppConfig's parts. Only SimConfig's are
// written into logs (serialize_config); the others are read from files only.
using Field = std::variant<std::int32_t SimConfig::*, float SimConfig::*, std::int32_t RealtimeConfig::*,
                           std::int32_t GraphBuildConfig::*, float GraphBuildConfig::*, float RecordingConfig::*>;

template <typename Member>
struct MemberOf;
template <typename Part, typename Value>
struct MemberOf<Value Part::*> {
    using part = Part;
    using value = Value;
};

SimConfig& part_of(AppConfig& c, const SimConfig*) { return c.sim; }
RealtimeConfig& part_of(AppConfig& c, const RealtimeConfig*) { return c.realtime; }
GraphBuildConfig& part_of(AppConfig& c, const GraphBuildConfig*) { return c.graph_build; }
RecordingConfig& part_of(AppConfig& c, const RecordingConfig*) { return c.recording; }
const SimConfig& part_of(const AppConfig& c, const SimConfig*) { return c.sim; }
const RealtimeConfig& part_of(const AppConfig& c, const RealtimeConfig*) { return c.realtime; }
const GraphBuildConfig& part_of(const AppConfig& c, const GraphBuildConfig*) { return c.graph_build; }
const RecordingConfig& part_of(const AppConfig& c, const RecordingConfig*) { return c.recording; }

// Calls visit(value) with a reference to the field's value in `config`.
template <typename Config, typename Visit>
void visit_field(Config& config, const Field& field, Visit&& visit) {
    std::visit(
        [&](auto member) {
            using Part = typename MemberOf<decltype(member)>::part;
            visit(part_of(config, static_cast<const Part*>(nullptr)).*member);
        },
        field);
}

bool is_integer(const Field& field) {
    return std::visit([](auto member) { return std::is_same_v<typename MemberOf<decltype(member)>::value, std::int32_t>; },
                      field);
}

struct KeySpec {
    const char* table;
    const char* key;
    Field field;
    double min;
    double max;
    const char* doc;
};

// The schema: one line per key. docs/config.md documents each (a test checks).
const KeySpec kKeys[] = {
    {"simulation", "tick_rate_hz", &SimConfig::tick_rate_hz, 30, 2000, "fixed simulation rate (ticks per second)"},
    {"simulation", "max_catch_up_ticks", &SimConfig::max_catch_up_ticks, 1, 1000, "most ticks run after one wake-up before the backlog is dropped"},
    {"puppet", "pelvis_height", &SimConfig::pelvis_height, 0.3, 2.0, "hip joint height above the ground when standing (m)"},
    {"puppet", "hip_width", &SimConfig::hip_width, 0.05, 0.6, "distance between the hip joints (m)"},
    {"puppet", "thigh_length", &SimConfig::thigh_length, 0.1, 1.0, "hip to knee (m)"},
    {"puppet", "shin_length", &SimConfig::shin_length, 0.1, 1.0, "knee to ankle (m)"},
    {"puppet", "ankle_height", &SimConfig::ankle_height, 0.01, 0.3, "ankle above the sole (m)"},
    {"puppet", "foot_length", &SimConfig::foot_length, 0.03, 0.5, "ankle to the ball of the foot (m)"},
    {"puppet", "toe_length", &SimConfig::toe_length, 0.01, 0.3, "ball of the foot to the tip of the toes (m)"},
    {"puppet", "spine_length", &SimConfig::spine_length, 0.2, 1.2, "pelvis to the base of the neck (m)"},
    {"puppet", "neck_length", &SimConfig::neck_length, 0.02, 0.4, "base of the neck to the head joint (m)"},
    {"puppet", "head_length", &SimConfig::head_length, 0.05, 0.5, "head joint to the top of the head (m)"},
    {"puppet", "shoulder_width", &SimConfig::shoulder_width, 0.1, 1.0, "distance between the shoulder joints (m)"},
    {"puppet", "upper_arm_length", &SimConfig::upper_arm_length, 0.05, 0.8, "shoulder to elbow (m)"},
    {"puppet", "forearm_length", &SimConfig::forearm_length, 0.05, 0.8, "elbow to wrist (m)"},
    {"puppet", "hand_length", &SimConfig::hand_length, 0.02, 0.4, "wrist to fingertips (m)"},
    {"locomotion", "max_speed", &SimConfig::max_speed, 0.1, 12.0, "speed at full stick deflection (m/s)"},
    {"locomotion", "walk_cycle_speed", &SimConfig::walk_cycle_speed, 0.1, 10.0, "speed at which the walk clip is fully blended in (m/s)"},
    {"locomotion", "stride_length", &SimConfig::stride_length, 0.2, 5.0, "distance covered by one walk cycle, two steps (m)"},
    {"locomotion", "acceleration", &SimConfig::acceleration, 0.1, 100.0, "how fast velocity follows the stick (m/s²)"},
    {"locomotion", "turn_rate_deg_s", &SimConfig::turn_rate_deg_s, 1.0, 3600.0, "how fast the heading follows the direction of travel (°/s)"},
    {"locomotion", "stick_deadzone", &SimConfig::stick_deadzone, 0.0, 0.9, "radial deadzone, fraction of full deflection"},
    {"locomotion", "response_curve", &SimConfig::response_curve, 0.0, 1.0, "0 linear … 1 quadratic response of speed to deflection"},
    // [realtime]: `marionette run` thread settings, applied at start only (RealtimeConfig: not in logs).
    {"realtime", "input_priority", &RealtimeConfig::input_priority, 0, 99, "SCHED_FIFO priority of the input thread (0: normal scheduling)"},
    {"realtime", "simulation_priority", &RealtimeConfig::simulation_priority, 0, 99, "SCHED_FIFO priority of the simulation thread (0: normal scheduling)"},
    {"realtime", "render_priority", &RealtimeConfig::render_priority, 0, 99, "SCHED_FIFO priority of the render thread (0: normal scheduling)"},
    {"realtime", "input_cpu", &RealtimeConfig::input_cpu, -1, 1023, "CPU the input thread is pinned to (-1: any)"},
    {"realtime", "simulation_cpu", &RealtimeConfig::simulation_cpu, -1, 1023, "CPU the simulation thread is pinned to (-1: any)"},
    {"realtime", "render_cpu", &RealtimeConfig::render_cpu, -1, 1023, "CPU the render thread is pinned to (-1: any)"},
    {"realtime", "lock_memory", &RealtimeConfig::lock_memory, 0, 1, "1: lock all memory (mlockall) before the threads start"},
    // [recording]: `marionette run --record auto` (docs/deploy.md), read at start only (RecordingConfig: not in logs).
    {"recording", "max_total_mb", &RecordingConfig::max_total_mb, 0.01, 1048576.0, "all recordings in the directory together; the oldest are deleted first (MB)"},
    {"recording", "max_file_mb", &RecordingConfig::max_file_mb, 0.01, 1048576.0, "one file of a recording; it continues in NAME.1, NAME.2, ... (MB)"},
    {"recording", "min_free_mb", &RecordingConfig::min_free_mb, 0.0, 1048576.0, "free space recording always leaves on the file system (MB)"},
    // [motion_graph] (docs/motion-graph.md): the build parameters (GraphBuildConfig: not in logs), then the
    // controller's keys, which the tick reads.
    {"motion_graph", "analysis_rate_hz", &GraphBuildConfig::graph_analysis_rate_hz, 5, 240, "rate clips are resampled to for the graph build"},
    {"motion_graph", "window_frames", &GraphBuildConfig::graph_window_frames, 2, 120, "k: frames in the distance window and in each transition"},
    {"motion_graph", "neighbourhood_frames", &GraphBuildConfig::graph_neighbourhood_frames, 1, 60, "local minima are taken over (2h+1)² frame pairs"},
    {"motion_graph", "threshold_percentile", &GraphBuildConfig::graph_threshold_percentile, 0.01, 100.0, "transition threshold as a percentile of all pair distances"},
    {"motion_graph", "threshold_absolute", &GraphBuildConfig::graph_threshold_absolute, 0.0, 100.0, "when > 0, the threshold itself (mean squared distance in leg lengths²)"},
    {"motion_graph", "bridge_percentile", &GraphBuildConfig::graph_bridge_percentile, 0.01, 100.0, "clips cut off from the component get their cheapest transitions below this percentile"},
    {"motion_graph", "contact_height", &GraphBuildConfig::graph_contact_height, 0.0, 1.0, "foot contact: height above the clip's ground, leg lengths"},
    {"motion_graph", "contact_speed", &GraphBuildConfig::graph_contact_speed, 0.0, 10.0, "foot contact: ground-plane speed, leg lengths per second"},
    {"motion_graph", "transition_weight", &SimConfig::graph_transition_weight, 0.0, 1000.0, "path cost: seconds charged per unit of transition distance"},
    {"motion_graph", "horizon_s", &SimConfig::graph_horizon_s, 0.1, 10.0, "controller: look-ahead of the stick-following search (s)"},
    {"motion_graph", "max_nodes_per_tick", &SimConfig::graph_max_nodes_per_tick, 1, 100000, "controller: search nodes expanded per tick at most"},
    {"motion_graph", "full_stick_speed", &SimConfig::graph_full_stick_speed, 0.1, 20.0, "controller: speed asked for at full stick (leg lengths per second)"},
    {"motion_graph", "leg_metres", &SimConfig::graph_leg_metres, 0.1, 5.0, "the graph's leg length is scaled to this (m)"},
    {"motion_graph", "attract_after_s", &SimConfig::graph_attract_after_s, 0.1, 86400.0, "seconds without input before the attract-mode random walk"},
    {"motion_graph", "attract_temperature", &SimConfig::graph_attract_temperature, 0.001, 1000.0, "attract walk: edge weight 1 / (1 + cost / temperature)"},
    {"motion_graph", "attract_seed", &SimConfig::graph_attract_seed, 0, 2147483647, "attract-mode random seed"},
    // [motion]: what poses the puppet (docs/motion-graph.md, "Motion sources"); `source` is kMotionSourceNames.
    {"motion", "crossfade_s", &SimConfig::motion_crossfade_s, 0.0, 5.0, "a live change of motion source cross-fades over this long (s)"},
    {"motion", "feet_release_s", &SimConfig::feet_release_s, 0.0, 2.0, "graph_feet: a lifted foot eases from its pin back to the clip's foot (s)"},
    {"motion", "feet_terrain_rate", &SimConfig::feet_terrain_rate, 0.1, 100.0, "graph_feet: how fast the body follows the ground height (1/s)"},
    // [motion_matching] (docs/motion-matching.md): feature weights, then the controller.
    {"motion_matching", "foot_position_weight", &SimConfig::matching_foot_position_weight, 0.0, 100.0, "weight of both feet's positions in the root frame"},
    {"motion_matching", "foot_velocity_weight", &SimConfig::matching_foot_velocity_weight, 0.0, 100.0, "weight of both feet's velocities"},
    {"motion_matching", "hips_velocity_weight", &SimConfig::matching_hips_velocity_weight, 0.0, 100.0, "weight of the hips' velocity"},
    {"motion_matching", "trajectory_position_weight", &SimConfig::matching_trajectory_position_weight, 0.0, 100.0, "weight of the future root positions (1/3, 2/3, 1 s)"},
    {"motion_matching", "trajectory_facing_weight", &SimConfig::matching_trajectory_facing_weight, 0.0, 100.0, "weight of the future facings (1/3, 2/3, 1 s)"},
    {"motion_matching", "search_interval_s", &SimConfig::matching_search_interval_s, 0.005, 2.0, "the database is searched at least this often (s)"},
    {"motion_matching", "search_threshold_m", &SimConfig::matching_search_threshold_m, 0.01, 10.0, "… and whenever the desired trajectory is this far from the playing frame's (m)"},
    {"motion_matching", "inertialization_s", &SimConfig::matching_inertialization_s, 0.01, 2.0, "a jump's pose offsets decay to zero over this long (s)"},
    {"motion_matching", "velocity_halflife_s", &SimConfig::matching_velocity_halflife_s, 0.01, 2.0, "halflife of the spring carrying the desired velocity toward the stick's (s)"},
    {"motion_matching", "facing_halflife_s", &SimConfig::matching_facing_halflife_s, 0.01, 2.0, "halflife of the spring carrying the desired facing toward the stick's (s)"},
    {"motion_matching", "correction_halflife_s", &SimConfig::matching_correction_halflife_s, 0.01, 2.0, "halflife of the pull of the character's root toward the desired trajectory (s)"},
    // [gait] (docs/gait.md); the prototypes are [gait.walk] and [gait.run], below.
    {"gait", "pelvis_height", &SimConfig::gait_pelvis_height, 0.3, 2.0, "hip height above the mean foot ground while stepping (m)"},
    {"gait", "step_length_multiplier", &SimConfig::step_length_multiplier, 0.05, 2.0, "step length = multiplier · sqrt(speed)"},
    {"gait", "min_step_duration", &SimConfig::min_step_duration, 0.1, 2.0, "shortest step (s)"},
    {"gait", "max_step_duration", &SimConfig::max_step_duration, 0.1, 3.0, "longest step (s)"},
    {"gait", "walk_duty", &SimConfig::walk_duty, 0.5, 0.9, "fraction of a cycle each foot is planted when walking"},
    {"gait", "run_duty", &SimConfig::run_duty, 0.1, 0.49, "fraction of a cycle each foot is planted when running"},
    {"gait", "run_threshold", &SimConfig::run_threshold, 0.1, 12.0, "speed above which the gait runs (m/s)"},
    {"gait", "swing_clearance", &SimConfig::swing_clearance, 0.0, 0.3, "height the swing sole keeps above the ground (m)"},
    {"gait", "spine_lean_deg_per_m_s", &SimConfig::spine_lean_deg_per_m_s, 0.0, 30.0, "forward spine lean per unit speed (°/(m/s))"},
    {"gait", "max_spine_lean_deg", &SimConfig::max_spine_lean_deg, 0.0, 45.0, "largest spine lean (°)"},
    {"gait", "interpolation_rate", &SimConfig::interpolation_rate, 0.1, 100.0, "how fast lean, walk/run blend and pelvis height follow their targets (1/s)"},
    {"gait", "slope_speed_factor", &SimConfig::slope_speed_factor, 0.0, 0.05, "speed reduction per degree of slope"},
    {"gait", "turn_in_place_deg", &SimConfig::turn_in_place_deg, 30.0, 180.0, "reversals wider than this turn in place (°)"},
    {"gait", "stop_transition_s", &SimConfig::stop_transition_s, 0.05, 1.0, "longest time the swing foot takes to plant after a stop (s)"},
    {"gait", "max_step_height", &SimConfig::max_step_height, 0.05, 1.0, "a box rising more than this above the ground beside it is an obstacle the puppet stops at (m)"},
    {"gait", "breath_amplitude", &SimConfig::breath_amplitude, 0.0, 0.05, "pelvis rise of a breath when idle (m)"},
    {"gait", "breath_period_s", &SimConfig::breath_period_s, 0.5, 20.0, "length of one breath (s)"},
};

// [motion] source, a string-valued key; the names index MotionSourceSetting.
constexpr const char* kMotionSourceNames[] = {"auto", "gait", "graph", "graph_feet", "matching"};
// [timing] interpolation, the other one (not the tick's: never serialized); the names index Interpolation.
constexpr const char* kInterpolationNames[] = {"interpolate", "extrapolate", "latest"};
constexpr const char* kInterpolationDoc =
    "what the render thread draws: interpolate (one tick behind), extrapolate or latest (the newest tick)";

void apply_motion_source(SimConfig& config, const toml::node& node, const std::string& file);
void apply_interpolation(TimingConfig& timing, const toml::node& node, const std::string& file);

bool is_sim_field(const Field& field) {
    return std::visit([](auto member) { return std::is_same_v<typename MemberOf<decltype(member)>::part, SimConfig>; }, field);
}

const KeySpec* find_key(std::string_view table, std::string_view key) {
    for (const KeySpec& k : kKeys)
        if (table == k.table && key == k.key) return &k;
    return nullptr;
}

int line_of(const toml::node& node) { return static_cast<int>(node.source().begin.line); }

std::string known_keys_of(std::string_view table) {
    std::string out;
    for (const KeySpec& k : kKeys)
        if (table == k.table) out += (out.empty() ? "" : ", ") + std::string(k.key);
    if (table == "motion_graph") out += ", buttons (the [motion_graph.buttons] table)";
    if (table == "timing") out = "interpolation";
    if (table == "ui") out = "enabled";
    return out;
}

std::string known_tables() {
    std::string out;
    std::string last;
    for (const KeySpec& k : kKeys)
        if (last != k.table) {
            out += (out.empty() ? "" : ", ") + std::string(k.table);
            last = k.table;
        }
    return out + ", terrain, timing, ui";
}

template <typename Number>
std::string format_number(Number v) {
    char buf[64];
    const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
    (void)ec;
    std::string s(buf, end);
    if (s.find_first_of(".eE") == std::string::npos && s.find("inf") == std::string::npos) s += ".0";
    return s;
}

// A key's value from `node`, checked against the key's type and range.
template <typename Value>
Value read_key_value(const toml::node& node, const KeySpec& spec, const std::string& file, const std::string& full) {
    const std::string range = "[" + format_number(spec.min) + ", " + format_number(spec.max) + "]";
    if constexpr (std::is_same_v<Value, std::int32_t>) {
        const auto* v = node.as_integer();
        if (!v) throw ConfigError(file, line_of(node), full, "expected an integer in " + range);
        const std::int64_t value = v->get();
        if (value < spec.min || value > spec.max)
            throw ConfigError(file, line_of(node), full,
                              std::to_string(value) + " is out of range: expected an integer in " + range);
        return static_cast<std::int32_t>(value);
    } else {
        double value = 0.0;
        if (const auto* f = node.as_floating_point()) value = f->get();
        else if (const auto* i = node.as_integer()) value = static_cast<double>(i->get());
        else throw ConfigError(file, line_of(node), full, "expected a number in " + range);
        if (!std::isfinite(value) || value < spec.min || value > spec.max)
            throw ConfigError(file, line_of(node), full,
                              format_number(value) + " is out of range: expected a number in " + range);
        return static_cast<float>(value);
    }
}

// The value of a SimConfig key as the effective text writes it (floats in the
// shortest text that reads back to the same bits); nothing for other parts' keys.
std::optional<std::string> sim_value_text(const SimConfig& config, const Field& field) {
    return std::visit(
        [&](auto member) -> std::optional<std::string> {
            using Member = MemberOf<decltype(member)>;
            if constexpr (!std::is_same_v<typename Member::part, SimConfig>) return std::nullopt;
            else if constexpr (std::is_same_v<typename Member::value, std::int32_t>) return std::to_string(config.*member);
            else return format_number(config.*member);
        },
        field);
}

// [terrain]: `name` (a built-in terrain or a file path) and/or inline data
// (heightfield, box, slope), which win when present: logs carry them inline.
void apply_terrain_table(SimConfig& config, const toml::table& table, const std::string& file) {
    std::string name = config.terrain_name;
    const Terrain inline_data = terrain_from_table(table, file, "terrain.");  // also rejects unknown keys
    if (const toml::node* n = table.get("name")) {
        const auto* s = n->as_string();
        if (!s) throw ConfigError(file, line_of(*n), "terrain.name", "expected a string: " + builtin_terrain_list() + " or a file path");
        name = s->get();
        if (!table_has_terrain_data(table)) {
            bool builtin = false;
            for (const char* b : kBuiltinTerrains) builtin = builtin || name == b || name == "builtin:" + std::string(b);
            if (!builtin && !std::ifstream(name))
                throw ConfigError(file, line_of(*n), "terrain.name",
                                  "no terrain '" + name + "' (expected " + builtin_terrain_list() + " or a readable file path)");
            config.terrain = load_terrain(name);
        }
    }
    if (table_has_terrain_data(table)) {
        config.terrain = inline_data;
        if (!table.contains("name")) name = "inline";
    }
    config.terrain_name = name;
}

// [gait.walk] / [gait.run]: swing_foot, pelvis, hand, each an array of
// [phase, x, y, z] keys (runtime/gait/gait_prototype.hpp says what x, y, z mean).
void apply_prototype_table(GaitPrototypes& out, const toml::node& node, const std::string& table, const std::string& file) {
    const toml::table* t = node.as_table();
    if (!t) throw ConfigError(file, line_of(node), table, "expected a table ([" + table + "]) of swing_foot, pelvis, hand");
    for (const auto& [key, value] : *t) {
        const std::string full = table + "." + std::string(key.str());
        SplinePrototype* target = nullptr;
        const bool open_path = key.str() == "swing_foot";
        if (key.str() == "swing_foot") target = &out.swing_foot;
        else if (key.str() == "pelvis") target = &out.pelvis;
        else if (key.str() == "hand") target = &out.hand;
        else throw ConfigError(file, line_of(value), full, "unknown key (expected one of: swing_foot, pelvis, hand)");
        const toml::array* keys = value.as_array();
        const std::string expected = "expected 2 to " + std::to_string(kMaxPrototypeKeys) + " keys [phase, x, y, z]";
        if (!keys || keys->size() < 2 || keys->size() > static_cast<std::size_t>(kMaxPrototypeKeys))
            throw ConfigError(file, line_of(value), full, expected);
        SplinePrototype p;
        for (const toml::node& k : *keys) {
            const toml::array* numbers = k.as_array();
            if (!numbers || numbers->size() != 4) throw ConfigError(file, line_of(k), full, expected);
            float v[4];
            for (std::size_t i = 0; i < 4; ++i) {
                const toml::node& n = *numbers->get(i);
                double d = 0.0;
                if (const auto* f = n.as_floating_point()) d = f->get();
                else if (const auto* in = n.as_integer()) d = static_cast<double>(in->get());
                else throw ConfigError(file, line_of(k), full, expected + " (numbers)");
                if (!std::isfinite(d) || std::fabs(d) > 10.0)
                    throw ConfigError(file, line_of(k), full, "values must be finite and within ±10");
                v[i] = static_cast<float>(d);
            }
            if (p.count > 0 && !(v[0] > p.keys[static_cast<std::size_t>(p.count - 1)].phase))
                throw ConfigError(file, line_of(k), full, "phases must increase from key to key");
            p.keys[static_cast<std::size_t>(p.count++)] = {v[0], v[1], v[2], v[3]};
        }
        const PrototypeKey& first = p.keys[0];
        const PrototypeKey& last = p.keys[static_cast<std::size_t>(p.count - 1)];
        if (first.phase != 0.0f || last.phase != 1.0f)
            throw ConfigError(file, line_of(value), full, "the first key's phase must be 0 and the last key's 1");
        if (open_path && !(first.x == 0.0f && first.y == 0.0f && first.z == 0.0f && last.x == 0.0f && last.y == 0.0f && last.z == 1.0f))
            throw ConfigError(file, line_of(value), full,
                              "a swing must start at [0, 0, 0, 0] and end at [1, 0, 0, 1] (on the planted positions)");
        if (!open_path && !(first.x == last.x && first.y == last.y && first.z == last.z))
            throw ConfigError(file, line_of(value), full, "a looping path must end with the values it starts with");
        *target = p;
    }
}

std::string serialize_prototypes(const GaitPrototypes& p, const std::string& table);

std::string toml_string(const std::string& s) {
    std::string out = "\"";
    for (char ch : s) {
        if (ch == '"' || ch == '\\') out += '\\';
        out += ch;
    }
    return out + "\"";
}

std::string read_file(const std::string& path) {
    // A directory opens as a stream and reads as empty, which would silently
    // mean "all defaults": refuse it by name.
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0)
        throw ConfigError(path, 0, "", std::string("cannot open the configuration file: ") + std::strerror(errno));
    if (S_ISDIR(st.st_mode)) throw ConfigError(path, 0, "", "is a directory, not a configuration file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw ConfigError(path, 0, "", std::string("cannot open the configuration file: ") + std::strerror(errno));
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) throw ConfigError(path, 0, "", std::string("cannot read the configuration file: ") + std::strerror(errno));
    return text;
}

// ---- [motion_graph.buttons] (docs/config.md): button name → graph label -------
constexpr std::size_t kMaxLabelLength = 64;

void apply_buttons_table(SimConfig& config, const toml::node& node, const std::string& file) {
    const toml::table* t = node.as_table();
    std::string names;
    for (const std::string_view n : kButtonNames) names += (names.empty() ? "" : ", ") + std::string(n);
    if (!t) throw ConfigError(file, line_of(node), "motion_graph.buttons", "expected a table ([motion_graph.buttons]) of button = \"label\"");
    for (const auto& [key, value] : *t) {
        const std::string full = "motion_graph.buttons." + std::string(key.str());
        const std::optional<Button> button = button_from_name(key.str());
        if (!button) throw ConfigError(file, line_of(value), full, "unknown button (expected one of: " + names + ")");
        const auto* label = value.as_string();
        if (!label) throw ConfigError(file, line_of(value), full, "expected a label name in quotes, or \"\" for none");
        const std::string& text = label->get();
        if (text.size() > kMaxLabelLength)
            throw ConfigError(file, line_of(value), full, "label longer than " + std::to_string(kMaxLabelLength) + " characters");
        for (const char ch : text)
            if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f)
                throw ConfigError(file, line_of(value), full, "a label may not contain control characters");
        GraphButtonBinding& b = config.graph_buttons[static_cast<std::size_t>(*button)];
        b.label = text;
        b.file = file;
        b.line = line_of(value);
    }
}

std::string serialize_buttons(const SimConfig& config) {
    std::string out = "\n[motion_graph.buttons]\n";
    for (std::size_t b = 0; b < kButtonNames.size(); ++b)
        out += std::string(kButtonNames[b]) + " = " + toml_string(config.graph_buttons[b].label) + "\n";
    return out;
}

}  // namespace

std::vector<ConfigKeyInfo> config_schema() {
    std::vector<ConfigKeyInfo> out;
    for (const KeySpec& k : kKeys)
        out.push_back({k.table, k.key, is_integer(k.field) ? "integer" : "float", k.min, k.max, k.doc,
                       is_sim_field(k.field) && std::string_view(k.table) != "puppet" &&
                           std::string_view(k.key) != "tick_rate_hz"});
    out.push_back({"motion", "source", "string", 0, 0, "what poses the puppet: auto, gait, graph, graph_feet or matching", true});
    out.push_back({"ui", "enabled", "boolean", 0, 0, "false locks the in-app tuning UI (a kiosk in service mode)"});
    out.push_back({"timing", "interpolation", "string", 0, 0, kInterpolationDoc});
    for (const std::string_view b : kButtonNames)
        out.push_back({"motion_graph.buttons", std::string(b), "string", 0.0, 0.0, "graph label played when the button is pressed, \"\" for none"});
    return out;
}

AppConfig apply_config_text(const AppConfig& base, std::string_view text, const std::string& file) {
    toml::table doc;
    try {
        doc = toml::parse(text, file);
    } catch (const toml::parse_error& e) {
        throw ConfigError(file, static_cast<int>(e.source().begin.line), "",
                          "TOML syntax error: " + std::string(e.description()));
    }
    AppConfig app = base;
    SimConfig& config = app.sim;
    for (const auto& [table_key, table_node] : doc) {
        const std::string table_name(table_key.str());
        const std::string known = known_keys_of(table_name);
        if (known.empty() && table_name != "terrain")
            throw ConfigError(file, line_of(table_node), table_name,
                              "unknown table (expected one of: " + known_tables() + ")");
        const toml::table* table = table_node.as_table();
        if (!table) throw ConfigError(file, line_of(table_node), table_name, "expected a table ([" + table_name + "])");
        if (table_name == "terrain") {
            apply_terrain_table(config, *table, file);
            continue;
        }
        for (const auto& [key, node] : *table) {
            const std::string full = table_name + "." + std::string(key.str());
            if (table_name == "motion" && key.str() == "source") {
                apply_motion_source(config, node, file);
                continue;
            }
            if (table_name == "ui" && key.str() == "enabled") {
                const auto* b = node.as_boolean();
                if (!b) throw ConfigError(file, line_of(node), full, "expected true or false");
                app.ui.enabled = b->get();
                continue;
            }
            if (table_name == "timing" && key.str() == "interpolation") {
                apply_interpolation(app.timing, node, file);
                continue;
            }
            if (table_name == "motion_graph" && key.str() == "buttons") {
                apply_buttons_table(config, node, file);
                continue;
            }
            if (table_name == "gait" && (key.str() == "walk" || key.str() == "run")) {
                apply_prototype_table(key.str() == "walk" ? config.walk : config.run, node, full, file);
                continue;
            }
            const KeySpec* spec = nullptr;
            for (const KeySpec& k : kKeys)
                if (table_name == k.table && key.str() == k.key) spec = &k;
            if (!spec)
                throw ConfigError(file, line_of(node), full, "unknown key (expected one of: " + known + ")");
            // A named reference: clang 14 cannot capture a structured binding in a lambda.
            const toml::node& key_node = node;
            visit_field(app, spec->field, [&](auto& value) {
                value = read_key_value<std::remove_reference_t<decltype(value)>>(key_node, *spec, file, full);
            });
        }
    }
    // Relations between keys.
    if (config.gait_pelvis_height >= config.thigh_length + config.shin_length + config.ankle_height)
        throw ConfigError(file, doc["gait"]["pelvis_height"].node() ? line_of(*doc["gait"]["pelvis_height"].node()) : 0,
                          "gait.pelvis_height", "must be less than thigh_length + shin_length + ankle_height, or the feet cannot reach");
    if (config.min_step_duration > config.max_step_duration)
        throw ConfigError(file, 0, "gait.min_step_duration", "must not exceed gait.max_step_duration");
    if (config.pelvis_height > config.thigh_length + config.shin_length + config.ankle_height + 1e-4f)
        throw ConfigError(file, doc["puppet"]["pelvis_height"].node() ? line_of(*doc["puppet"]["pelvis_height"].node()) : 0,
                          "puppet.pelvis_height",
                          "must not exceed thigh_length + shin_length + ankle_height, or the feet cannot reach the ground");
    return app;
}

namespace {
void apply_motion_source(SimConfig& config, const toml::node& node, const std::string& file) {
    const auto* s = node.as_string();
    for (std::size_t i = 0; s && i < std::size(kMotionSourceNames); ++i)
        if (s->get() == kMotionSourceNames[i]) {
            config.motion_source = static_cast<MotionSourceSetting>(i);
            return;
        }
    throw ConfigError(file, line_of(node), "motion.source",
                      (s ? "'" + s->get() + "' is not a motion source" : std::string("expected a string")) +
                          " (expected \"auto\", \"gait\", \"graph\", \"graph_feet\" or \"matching\")");
}

void apply_interpolation(TimingConfig& timing, const toml::node& node, const std::string& file) {
    const auto* s = node.as_string();
    for (std::size_t i = 0; s && i < std::size(kInterpolationNames); ++i)
        if (s->get() == kInterpolationNames[i]) {
            timing.interpolation = static_cast<Interpolation>(i);
            return;
        }
    throw ConfigError(file, line_of(node), "timing.interpolation",
                      (s ? "'" + s->get() + "' is not an interpolation" : std::string("expected a string")) +
                          " (expected \"interpolate\", \"extrapolate\" or \"latest\")");
}
}  // namespace

std::optional<std::string> config_value_text(const AppConfig& config, std::string_view table, std::string_view key) {
    const KeySpec* spec = find_key(table, key);
    if (!spec) return std::nullopt;
    std::string out;
    visit_field(config, spec->field, [&](const auto& value) {
        if constexpr (std::is_same_v<std::remove_cvref_t<decltype(value)>, std::int32_t>) out = std::to_string(value);
        else out = format_number(value);
    });
    return out;
}

std::optional<double> config_number(const AppConfig& config, std::string_view table, std::string_view key) {
    const KeySpec* spec = find_key(table, key);
    if (!spec) return std::nullopt;
    double out = 0.0;
    visit_field(config, spec->field, [&](const auto& value) { out = static_cast<double>(value); });
    return out;
}

std::string interpolation_name(Interpolation mode) { return kInterpolationNames[static_cast<std::size_t>(mode)]; }

std::string motion_source_name(MotionSourceSetting source) {
    return kMotionSourceNames[static_cast<std::size_t>(source)];
}

std::string_view default_config_text() { return embedded::find("config/marionette.toml"); }

AppConfig default_config() { return apply_config_text(AppConfig{}, default_config_text(), "config/marionette.toml"); }

AppConfig load_config(const std::string& user_file) {
    AppConfig config = default_config();
    if (!user_file.empty()) config = apply_config_text(config, read_file(user_file), user_file);
    return config;
}

std::string serialize_config(const SimConfig& config) {
    std::string out = "# marionette effective configuration\n";
    std::string table;
    for (const KeySpec& k : kKeys) {
        const std::optional<std::string> value = sim_value_text(config, k.field);
        if (!value) continue;  // [realtime] and the graph build keys: the tick never reads them
        if (table != k.table) {
            table = k.table;
            out += "\n[" + table + "]\n";
            if (table == "motion") out += "source = " + toml_string(motion_source_name(config.motion_source)) + "\n";
        }
        out += std::string(k.key) + " = " + *value + "\n";
    }
    out += serialize_prototypes(config.walk, "gait.walk");
    out += serialize_prototypes(config.run, "gait.run");
    out += serialize_buttons(config);
    // The terrain, resolved and inline: the text alone determines the ground. An
    // empty one (every feature edited away) has no inline data to win over its
    // name, so it is named as the built-in empty terrain.
    const Terrain& t = config.terrain;
    const bool empty = t.boxes.empty() && t.slopes.empty() && !(t.heightfield.nx >= 2 && t.heightfield.nz >= 2);
    out += "\n[terrain]\nname = " + toml_string(empty ? std::string("flat") : config.terrain_name) + "\n";
    out += serialize_terrain(config.terrain, "terrain.");
    return out;
}

namespace {
std::string serialize_prototypes(const GaitPrototypes& p, const std::string& table) {
    std::string out = "\n[" + table + "]   # keys [phase, x, y, z] (docs/gait.md)\n";
    const std::pair<const char*, const SplinePrototype*> paths[] = {{"swing_foot", &p.swing_foot}, {"pelvis", &p.pelvis}, {"hand", &p.hand}};
    for (const auto& [name, proto] : paths) {
        out += std::string(name) + " = [";
        for (int i = 0; i < proto->count; ++i) {
            const PrototypeKey& k = proto->keys[static_cast<std::size_t>(i)];
            out += std::string(i ? ", " : "") + "[" + format_number(k.phase) + ", " + format_number(k.x) + ", " + format_number(k.y) +
                   ", " + format_number(k.z) + "]";
        }
        out += "]\n";
    }
    return out;
}
}  // namespace

AppConfig config_from_text(std::string_view text, const std::string& origin) {
    return apply_config_text(default_config(), text, origin);
}

SimConfig apply_config_change(const SimConfig& running, std::string_view text, const std::string& origin) {
    AppConfig app = default_config();
    app.sim = running;
    return apply_config_text(app, text, origin).sim;
}

}  // namespace marionette
