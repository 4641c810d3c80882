#pragma once
// Motion-graph files for the commands: loading a .mgraph (errors name the file
// and byte) and the build parameters a configuration gives.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "motion_graph/graph_builder.hpp"
#include "runtime/motion_graph.hpp"
#include "runtime/sim_config.hpp"
#include "runtime/simulation.hpp"

namespace marionette {

MotionGraph load_motion_graph_file(const std::string& path);
// `--graph` on record, replay and run: a .mgraph file, or "default" for the
// embedded default graph built from the configuration's [motion_graph]
// parameters (identical bytes every time, so a log recorded with it replays with it).
// An empty argument gives the default graph when the configuration's [motion]
// source is graph or graph_feet, and no graph (nullptr) otherwise.
std::shared_ptr<const MotionGraph> load_graph_argument(const std::string& argument, const SimConfig& config);
void write_binary_file(const std::string& path, const std::vector<std::uint8_t>& bytes);
graph::GraphBuildParams graph_build_params(const SimConfig& config);

// Drives `sim` from `graph` (`--graph` on record, replay and run): the
// controller's settings from the simulation's [motion_graph] keys (horizon, nodes
// per tick, full-stick speed, leg scale, attract mode), and the face buttons south/east/west/north mapped to the labels
// jump/wave/bow/look_around where the graph has them.
void attach_motion_graph(Simulation& sim, std::shared_ptr<const MotionGraph> graph);

}  // namespace marionette
