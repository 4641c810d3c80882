#pragma once
// Motion-graph files for the commands: loading a .mgraph (errors name the file
// and byte) and the build parameters a configuration gives.
#include <cstdint>
#include <string>
#include <vector>

#include "motion_graph/graph_builder.hpp"
#include "runtime/motion_graph.hpp"
#include "runtime/sim_config.hpp"

namespace marionette {

MotionGraph load_motion_graph_file(const std::string& path);
void write_binary_file(const std::string& path, const std::vector<std::uint8_t>& bytes);
graph::GraphBuildParams graph_build_params(const SimConfig& config);

}  // namespace marionette
