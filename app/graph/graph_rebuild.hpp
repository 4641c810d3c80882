#pragma once
// Building a .mgraph from its source files, the one code path `graph build` and
// the stale-graph rebuild of `run --graph` / `record --graph` share, and the
// stale check itself (docs/motion-graph.md, "Stale graphs").
#include <memory>
#include <string>
#include <vector>

#include "graph_builder/clip_database.hpp"
#include "graph_builder/graph_builder.hpp"
#include "runtime/graph/motion_graph.hpp"
#include "app/config/app_config.hpp"

namespace marionette {

// What a graph is built from: an optional ASF skeleton (for AMC clips), the clip
// files, and a labels file ("" = the embedded config/graph_labels.toml).
struct GraphSources {
    std::string asf;
    std::vector<std::string> clips;
    std::string labels;
};

// Loads the label rules and the clip database (throws ImportError naming the file).
// With `retarget_to` (the puppet's skeleton), clips of any other humanoid
// skeleton are retargeted onto it as they load (docs/retarget.md).
offline::ClipDatabase load_graph_sources(const GraphSources& sources, double analysis_rate_hz,
                                         const Skeleton* retarget_to = nullptr);

// Builds the pruned graph from a database loaded by load_graph_sources and
// records the sources in it (so the file can be rebuilt when stale). Throws
// std::runtime_error when no strongly connected component remains.
offline::GraphBuildOutput build_graph_from_sources(const offline::ClipDatabase& db, const GraphSources& sources,
                                                 const offline::GraphBuildParams& params,
                                                 const offline::GraphBuildHooks& hooks = {});

// Writes `bytes` to a temporary file beside `path` and renames it over `path`,
// so a reader never sees a half-written file.
void write_binary_file_atomically(const std::string& path, const std::vector<std::uint8_t>& bytes);

// `--graph` on run and record: like load_graph_argument (empty or "default": just
// that), but a .mgraph whose
// recorded sources all exist and now hash differently (clips or labels edited,
// or the configuration's [motion_graph] build parameters changed) is rebuilt
// from them with the current parameters and written back atomically, with one
// line on stderr saying why. Missing sources: the file is used as it is, with a
// warning. A graph without recorded sources (e.g. `graph build --default`) is
// used as it is. A graph on the puppet's skeleton is rebuilt with its clips
// retargeted onto the puppet, as `graph build` made it. Replay must not use this: a rebuilt graph has other bytes than
// the one the log was recorded with.
std::shared_ptr<const MotionGraph> load_graph_argument_rebuilding_stale(const std::string& argument,
                                                                        const SimConfig& config,
                                                                        const GraphBuildConfig& build);

}  // namespace marionette
