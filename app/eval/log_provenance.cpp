#include "app/eval/log_provenance.hpp"

#include <xxhash.h>

#include <filesystem>
#include <sstream>

#include <fmt/format.h>

#include "app/graph/default_graph.hpp"
#include "app/graph/graph_files.hpp"
#include "app/io/files.hpp"
#include "runtime/errors/import_error.hpp"

#ifndef MARIONETTE_VERSION
#define MARIONETTE_VERSION "unknown"
#endif
#ifndef MARIONETTE_BUILD_TYPE
#define MARIONETTE_BUILD_TYPE "unknown"
#endif

namespace marionette {

namespace {

const char* compiler_name() {
#if defined(__clang__)
    return "Clang " __clang_version__;
#elif defined(__GNUC__)
    return "GCC " __VERSION__;
#else
    return "unknown compiler";
#endif
}

const char* architecture_name() {
#if defined(__x86_64__)
    return "x86_64";
#elif defined(__aarch64__)
    return "aarch64";
#elif defined(__i386__)
    return "i386";
#elif defined(__arm__)
    return "arm";
#else
    return "unknown architecture";
#endif
}

std::string hash_hex(const std::vector<std::uint8_t>& bytes) {
    return fmt::format("{:016x}", XXH64(bytes.data(), bytes.size(), 0));
}

}  // namespace

std::string build_provenance() {
    const std::string build_type = MARIONETTE_BUILD_TYPE;
    return fmt::format("marionette {}; {}; {}; {}", MARIONETTE_VERSION, compiler_name(), architecture_name(),
                       build_type.empty() ? std::string("no build type") : build_type);
}

std::string motion_graph_content_hash(const MotionGraph& graph) { return hash_hex(serialize_motion_graph(graph)); }

std::string motion_data_reference(const std::string& graph_argument, const MotionGraph* graph) {
    if (graph == nullptr) return "";
    const std::string hash = motion_graph_content_hash(*graph);
    if (graph_argument.empty() || graph_argument == "default") return "default-graph " + hash;
    return "graph-file " + hash + " " + std::filesystem::absolute(graph_argument).lexically_normal().string();
}

std::shared_ptr<const MotionGraph> graph_for_log(const InputLogHeader& header, const std::string& log_name,
                                                 const std::string& graph_argument, const AppConfig& recorded) {
    if (!graph_argument.empty() || header.motion_data.empty()) return load_graph_argument(graph_argument, recorded.sim, recorded.graph_build);
    std::istringstream words(header.motion_data);
    std::string kind, hash;
    words >> kind >> hash;
    std::string path;
    std::getline(words >> std::ws, path);
    if (kind == "default-graph") {
        auto graph = load_graph_argument("default", recorded.sim, recorded.graph_build);
        if (motion_graph_content_hash(*graph) != hash)
            throw ImportError(log_name, 0,
                              fmt::format("recorded with the embedded default graph {}, but this build's default graph is {} "
                                          "(the recording build: {})",
                                          hash, motion_graph_content_hash(*graph), header.provenance));
        return graph;
    }
    if (kind == "graph-file" && !path.empty()) {
        std::error_code ec;
        if (std::filesystem::is_regular_file(path, ec) && hash_hex(read_binary_file(path)) == hash)
            return std::make_shared<const MotionGraph>(load_motion_graph_file(path));
        throw ImportError(log_name, 0,
                          fmt::format("recorded with the motion graph {} (content hash {}), which is {}: pass that graph "
                                      "with --graph",
                                      path, hash, ec || !std::filesystem::exists(path, ec) ? "not there" : "changed since"));
    }
    throw ImportError(log_name, 0, "the header names motion data this build does not know: '" + header.motion_data + "'");
}

}  // namespace marionette
