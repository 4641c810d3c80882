#pragma once
// What an input log says about the build that recorded it and the motion data it
// needs (docs/input-log.md, version 2 header; docs/determinism.md), and the
// checks replay makes against it.
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>

#include "runtime/formats/input_log.hpp"
#include "runtime/graph/motion_graph.hpp"
#include "app/config/app_config.hpp"

namespace marionette {

// "marionette 0.1.0; GCC 12.2.0; x86_64; RelWithDebInfo": version, compiler,
// architecture and build type of this build.
std::string build_provenance();

// The XXH64 of a graph's .mgraph bytes, 16 hex digits.
std::string motion_graph_content_hash(const MotionGraph& graph);

// The header's motion_data line for a recording: "" without a graph,
// "default-graph HASH" for the embedded default graph (an empty or "default"
// `--graph`), "graph-file HASH ABSOLUTE_PATH" for a .mgraph file.
std::string motion_data_reference(const std::string& graph_argument, const MotionGraph* graph);

// The graph a log needs. An explicit `--graph` wins. Otherwise the header's
// motion_data decides: the embedded default graph, or the recorded file when it
// still exists with the recorded content hash; else an ImportError naming the
// graph to pass. Version 1 logs (no motion_data) fall back to what the log's
// configuration asks for (the default graph for a graph source).
std::shared_ptr<const MotionGraph> graph_for_log(const InputLogHeader& header, const std::string& log_name,
                                                 const std::string& graph_argument, const AppConfig& recorded);

// A replay whose state hash differs from a checkpoint the recorder stored.
class ReplayDesync : public std::runtime_error {
public:
    ReplayDesync(std::uint64_t tick, const std::string& message) : std::runtime_error(message), tick_(tick) {}
    std::uint64_t tick() const { return tick_; }

private:
    std::uint64_t tick_;
};

}  // namespace marionette
