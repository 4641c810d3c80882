#include "app/graph/graph_files.hpp"
#include "app/io/log.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "app/config/config.hpp"
#include "app/graph/default_graph.hpp"
#include "app/io/files.hpp"

namespace marionette {

MotionGraph load_motion_graph_file(const std::string& path) {
    const std::vector<std::uint8_t> bytes = read_binary_file(path);
    return deserialize_motion_graph(bytes, path);
}

void write_binary_file(const std::string& path, const std::vector<std::uint8_t>& bytes) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error(path + ": cannot create file: " + std::strerror(errno));
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) throw std::runtime_error(path + ": write failed: " + std::strerror(errno));
}

offline::GraphBuildParams graph_build_params(const GraphBuildConfig& c) {
    offline::GraphBuildParams p;
    p.analysis_rate_hz = c.graph_analysis_rate_hz;
    p.window_frames = c.graph_window_frames;
    p.neighbourhood_frames = c.graph_neighbourhood_frames;
    p.threshold_percentile = c.graph_threshold_percentile;
    p.threshold_absolute = c.graph_threshold_absolute;
    p.bridge_percentile = c.graph_bridge_percentile;
    p.contact_height = c.graph_contact_height;
    p.contact_speed = c.graph_contact_speed;
    return p;
}

std::shared_ptr<const MotionGraph> load_graph_argument(const std::string& argument, const SimConfig& config,
                                                       const GraphBuildConfig& build) {
    if (argument.empty()) {
        const bool wants_graph = config.motion_source == MotionSourceSetting::graph ||
                                 config.motion_source == MotionSourceSetting::graph_feet ||
                                 config.motion_source == MotionSourceSetting::matching;
        if (!wants_graph) return nullptr;
        return std::make_shared<const MotionGraph>(build_default_motion_graph(config, build));
    }
    if (argument == "default") return std::make_shared<const MotionGraph>(build_default_motion_graph(config, build));
    return std::make_shared<const MotionGraph>(load_motion_graph_file(argument));
}

std::array<std::int32_t, kGraphActionButtons> resolve_graph_buttons(const SimConfig& config, const MotionGraph& graph,
                                                                    const std::string& graph_name) {
    static_assert(kButtonCount <= kGraphActionButtons, "every TickInput button needs a controller slot");
    std::array<std::int32_t, kGraphActionButtons> out{};
    out.fill(-1);
    const auto defaults = default_graph_buttons();
    const std::string labels = graph.labels.empty() ? std::string("none") : fmt::format("{}", fmt::join(graph.labels, ", "));
    std::string unmapped;
    for (std::size_t b = 0; b < kButtonNames.size(); ++b) {
        const GraphButtonBinding& binding = config.graph_buttons[b];
        if (binding.label.empty()) continue;
        out[b] = graph.label_index(binding.label);
        if (out[b] >= 0) continue;
        const std::string key = "motion_graph.buttons." + std::string(kButtonNames[b]);
        if (binding.label != defaults[b].label)
            throw ConfigError(binding.file.empty() ? std::string("configuration") : binding.file, binding.line, key,
                              "label '" + binding.label + "' is not in " + graph_name + " (its labels: " + labels +
                                  "; or \"\" for none)");
        unmapped += fmt::format("{}{} = \"{}\"", unmapped.empty() ? "" : ", ", kButtonNames[b], binding.label);
    }
    if (!unmapped.empty())
        log_message(LogLevel::warning, fmt::format("warning: {} has no label for the default [motion_graph.buttons] {} (its labels: {}); those buttons do nothing",
                   graph_name, unmapped, labels));
    return out;
}

double graph_metres_per_unit(const MotionGraph& graph, const Skeleton& puppet, const SimConfig& config) {
    // A graph of the puppet's own skeleton (the default graph) is in the puppet's
    // metres already; any other is scaled so its leg is leg_metres long.
    const bool puppet_skeleton = graph.skeleton.joint_names == puppet.joint_names && graph.skeleton.parents == puppet.parents;
    const double leg = graph.leg_length > 0.0f ? graph.leg_length : 1.0;
    return puppet_skeleton ? 1.0 : config.graph_leg_metres / leg;
}

void attach_motion_graph(Simulation& sim, std::shared_ptr<const MotionGraph> graph, const std::string& graph_name) {
    const SimConfig& sim_config = sim.config();
    GraphControllerConfig config;
    const double leg = graph->leg_length > 0.0f ? graph->leg_length : 1.0;
    config.horizon_s = sim_config.graph_horizon_s;
    config.max_nodes_per_tick = sim_config.graph_max_nodes_per_tick;
    config.max_speed = sim_config.graph_full_stick_speed * leg;
    config.transition_weight = sim_config.graph_transition_weight;
    config.attract_after_s = sim_config.graph_attract_after_s;
    config.attract_temperature = sim_config.graph_attract_temperature;
    config.seed = static_cast<std::uint64_t>(sim_config.graph_attract_seed);
    config.button_label = resolve_graph_buttons(sim_config, *graph, graph_name);
    const double metres_per_unit = graph_metres_per_unit(*graph, sim.skeleton(), sim_config);
    sim.use_motion_graph(std::move(graph), config, metres_per_unit);
}

}  // namespace marionette
