#include "app/graph_files.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "app/default_graph.hpp"
#include "app/files.hpp"

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

graph::GraphBuildParams graph_build_params(const SimConfig& c) {
    graph::GraphBuildParams p;
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

std::shared_ptr<const MotionGraph> load_graph_argument(const std::string& argument, const SimConfig& config) {
    if (argument.empty()) {
        const bool wants_graph = config.motion_source == MotionSourceSetting::graph ||
                                 config.motion_source == MotionSourceSetting::graph_feet;
        if (!wants_graph) return nullptr;
        return std::make_shared<const MotionGraph>(build_default_motion_graph(config));
    }
    if (argument == "default") return std::make_shared<const MotionGraph>(build_default_motion_graph(config));
    return std::make_shared<const MotionGraph>(load_motion_graph_file(argument));
}

void attach_motion_graph(Simulation& sim, std::shared_ptr<const MotionGraph> graph) {
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
    const char* const labels[4] = {"jump", "wave", "bow", "look_around"};
    for (int b = 0; b < 4; ++b) config.button_label[static_cast<size_t>(b)] = graph->label_index(labels[b]);
    // A graph of the puppet's own skeleton (the default graph) is in the puppet's
    // metres already; any other is scaled so its leg is leg_metres long.
    const Skeleton& puppet = sim.skeleton();
    const bool puppet_skeleton = graph->skeleton.joint_names == puppet.joint_names && graph->skeleton.parents == puppet.parents;
    const double metres_per_unit = puppet_skeleton ? 1.0 : sim_config.graph_leg_metres / leg;
    sim.use_motion_graph(std::move(graph), config, metres_per_unit);
}

}  // namespace marionette
