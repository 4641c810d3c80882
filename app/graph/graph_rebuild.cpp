#include "app/graph/graph_rebuild.hpp"
#include "app/io/log.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "app/config/embedded.hpp"
#include "app/io/files.hpp"
#include "app/graph/graph_files.hpp"
#include "retarget/retarget.hpp"
#include "runtime/gait/puppet.hpp"

namespace marionette {

offline::ClipDatabase load_graph_sources(const GraphSources& s, double analysis_rate_hz, const Skeleton* retarget_to) {
    const offline::LabelRules rules =
        s.labels.empty()
            ? offline::parse_label_rules(std::string(embedded::find("config/graph_labels.toml")), "config/graph_labels.toml")
            : offline::parse_label_rules(read_text_file(s.labels), s.labels);
    return offline::load_clip_database(s.clips, s.asf, rules, analysis_rate_hz, retarget_to);
}

offline::GraphBuildOutput build_graph_from_sources(const offline::ClipDatabase& db, const GraphSources& s,
                                                 const offline::GraphBuildParams& params,
                                                 const offline::GraphBuildHooks& hooks) {
    offline::GraphBuildOutput out = offline::build_motion_graph(db, params, hooks);
    MotionGraph& g = out.graph;
    g.source_asf = s.asf;
    g.source_clips = db.source_files;
    g.source_labels = s.labels;
    if (g.nodes.empty())
        throw std::runtime_error(fmt::format(
            "no strongly connected component: {} candidate transitions at threshold {:.4g} leave no cycle "
            "(raise motion_graph.threshold_percentile)",
            out.candidates.size(), out.threshold));
    return out;
}

void write_binary_file_atomically(const std::string& path, const std::vector<std::uint8_t>& bytes) {
    const std::string temp = path + fmt::format(".tmp{}", static_cast<long>(getpid()));
    write_binary_file(temp, bytes);
    std::error_code ec;
    std::filesystem::rename(temp, path, ec);
    if (ec) {
        std::filesystem::remove(temp);
        throw std::runtime_error(path + ": cannot replace the file: " + ec.message());
    }
}

std::shared_ptr<const MotionGraph> load_graph_argument_rebuilding_stale(const std::string& argument,
                                                                        const SimConfig& config,
                                                                        const GraphBuildConfig& build) {
    if (argument.empty() || argument == "default") return load_graph_argument(argument, config, build);
    const std::vector<std::uint8_t> bytes = read_binary_file(argument);
    const std::uint64_t stored_hash = motion_graph_source_hash(bytes, argument);  // header only: cheap
    auto graph = std::make_shared<MotionGraph>(deserialize_motion_graph(bytes, argument));
    if (graph->source_clips.empty()) return graph;  // nothing recorded to rebuild from
    const GraphSources sources{graph->source_asf, graph->source_clips, graph->source_labels};
    std::vector<std::string> missing;
    std::error_code ec;
    const auto check = [&](const std::string& path) {
        if (!path.empty() && !std::filesystem::is_regular_file(path, ec)) missing.push_back(path);
    };
    check(sources.asf);
    for (const std::string& c : sources.clips) check(c);
    check(sources.labels);
    if (!missing.empty()) {
        log_message(LogLevel::warning,
                    fmt::format("warning: {}: {} of its source files {} missing (first: {}); using the graph as it is, "
                                "unchecked for staleness",
                                argument, missing.size(), missing.size() == 1 ? "is" : "are", missing.front()));
        return graph;
    }
    offline::GraphBuildParams params = graph_build_params(build);
    const auto started = std::chrono::steady_clock::now();
    const Skeleton puppet = make_puppet_skeleton(config);
    const bool on_puppet = retarget::is_puppet_skeleton(graph->skeleton, puppet);
    const offline::ClipDatabase db = load_graph_sources(sources, params.analysis_rate_hz, on_puppet ? &puppet : nullptr);
    const std::uint64_t current_hash = offline::graph_source_hash(db.content_hash, params);
    if (current_hash == stored_hash) return graph;
    offline::GraphBuildOutput out = build_graph_from_sources(db, sources, params);
    // The file keeps build_seconds 0 (same sources, same bytes); the time is only printed.
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    write_binary_file_atomically(argument, serialize_motion_graph(out.graph));
    log_message(LogLevel::notice,
                fmt::format("{}: stale (source hash {:016x}, its {} source files and the [motion_graph] build parameters now "
                            "hash {:016x}): rebuilt in {:.2f} s and written back",
                            argument, stored_hash,
                            sources.clips.size() + (sources.asf.empty() ? 0 : 1) + (sources.labels.empty() ? 0 : 1),
                            current_hash, seconds));
    return std::make_shared<const MotionGraph>(std::move(out.graph));
}

}  // namespace marionette
