#pragma once
// The embedded default motion graph: the project's own action clips
// (config/clips/*.bvh, compiled into the binary) plus locomotion captured from
// the procedural gait over fixed stick programs, built with the graph_builder/
// builder and pruned so that every label survives. Needs no files at run time
// and gives identical bytes on every run (docs/motion-graph.md, "The default graph").
#include <string>
#include <vector>

#include "graph_builder/graph_builder.hpp"
#include "runtime/anim/clip.hpp"
#include "runtime/graph/motion_graph.hpp"
#include "app/config/app_config.hpp"

namespace marionette {

// Names of the embedded action clips, in database order.
const std::vector<std::string>& default_action_clip_names();  // wave, bow, jump, look_around
// The labels the default graph must keep (fails when one is cut off).
const std::vector<std::string>& default_graph_labels();

// The embedded action clips, imported with runtime/formats/bvh.hpp (throws ImportError
// naming the embedded path if one is malformed or missing).
std::vector<Clip> default_action_clips();

// Locomotion captured from the Simulation (procedural gait) over built-in stick
// programs, sampled at `rate_hz`: idle, walks and runs at several speeds, turns
// left and right, start and stop. Deterministic (the simulation is).
std::vector<Clip> generate_locomotion_clips(const SimConfig& config, double rate_hz);

struct DefaultGraphBuild {
    offline::GraphBuildOutput output;  // output.graph is the pruned default graph
    int clips = 0;
    double build_ms = 0.0;           // wall time; not stored in the graph
};

// Clips (locomotion captured from the gait of `config`) → database (embedded
// config/graph_labels.toml labels) → builder with the [motion_graph] build
// parameters `build_config` → pruned graph. The graph's build_seconds
// stays 0 so its serialized bytes depend only on the inputs. Throws
// std::runtime_error naming the label and why when a required label is cut off.
// `hooks` as for offline::build_motion_graph (progress, plot size). `threads`:
// the builder's worker threads (0: all cores; 1 starts no thread); the bytes are
// the same for any count.
DefaultGraphBuild build_default_motion_graph_report(const SimConfig& config, const GraphBuildConfig& build_config,
                                                    const offline::GraphBuildHooks& hooks = {}, int threads = 0);
MotionGraph build_default_motion_graph(const SimConfig& config, const GraphBuildConfig& build_config, int threads = 0);

}  // namespace marionette
