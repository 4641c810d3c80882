#pragma once
// Motion-graph files for the commands: loading a .mgraph (errors name the file
// and byte) and the build parameters a configuration gives.
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "graph_builder/graph_builder.hpp"
#include "runtime/graph/motion_graph.hpp"
#include "app/config/app_config.hpp"
#include "runtime/sim/simulation.hpp"

namespace marionette {

MotionGraph load_motion_graph_file(const std::string& path);
// `--graph` on record, replay and run: a .mgraph file, or "default" for the
// embedded default graph, captured from the gait of `config` and built with the
// [motion_graph] build parameters `build` (identical bytes every time, so a log
// recorded with it replays with it).
// An empty argument gives the default graph when the configuration's [motion]
// source is graph or graph_feet, and no graph (nullptr) otherwise.
std::shared_ptr<const MotionGraph> load_graph_argument(const std::string& argument, const SimConfig& config,
                                                       const GraphBuildConfig& build);
void write_binary_file(const std::string& path, const std::vector<std::uint8_t>& bytes);
offline::GraphBuildParams graph_build_params(const GraphBuildConfig& config);

// [motion_graph.buttons] resolved against the graph's labels: button bit → label
// index, −1 for none. A label the graph lacks is a ConfigError naming the key and
// the file:line that set it, unless it is the key's shipped default: then one
// warning line on stderr and the button does nothing (docs/config.md).
std::array<std::int32_t, kGraphActionButtons> resolve_graph_buttons(const SimConfig& config, const MotionGraph& graph,
                                                                    const std::string& graph_name);

// Metres per graph unit when a graph drives a puppet with skeleton `puppet`: 1 for
// a graph of the puppet's own skeleton (the default graph), else leg_metres / the
// graph's leg length.
double graph_metres_per_unit(const MotionGraph& graph, const Skeleton& puppet, const SimConfig& config);

// Drives `sim` from `graph` (`--graph` on record, replay, run and gait-eval): the
// controller's settings from the simulation's [motion_graph] keys (horizon, nodes
// per tick, full-stick speed, leg scale, attract mode) and its buttons from
// [motion_graph.buttons] (resolve_graph_buttons). `graph_name` names the graph in
// messages.
void attach_motion_graph(Simulation& sim, std::shared_ptr<const MotionGraph> graph,
                         const std::string& graph_name = "the motion graph");

}  // namespace marionette
