// `marionette graph build | info | path`: building motion graphs from clips,
// inspecting them, and searching paths through them (docs/motion-graph.md).
#include <fmt/format.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <set>

#include "app/cli/cli.hpp"
#include "app/cli/key_pose_commands.hpp"
#include "app/io/log.hpp"
#include "app/config/config.hpp"
#include "app/graph/default_graph.hpp"
#include "app/config/embedded.hpp"
#include "app/io/files.hpp"
#include "render_es/image.hpp"
#include "app/graph/graph_files.hpp"
#include "app/graph/graph_rebuild.hpp"
#include "app/io/json.hpp"
#include "graph_builder/graph_builder.hpp"
#include "runtime/graph/graph_path.hpp"
#include "render_es/image.hpp"
#include "runtime/formats/bvh.hpp"
#include "runtime/gait/puppet.hpp"
#include "runtime/graph/graph_path.hpp"

namespace marionette {

namespace {

struct GraphBuildCommandOptions {
    std::string asf_file;
    std::vector<std::string> clip_files;
    std::string output_file;
    std::string labels_file;
    std::string config_file;
    std::string plot_file;
    std::string dot_file;
    int threads = 0;
    bool json = false;
    bool keep_skeleton = false;  // --keep-skeleton: no retargeting onto the puppet
    bool default_graph = false;  // --default: the embedded default graph (app/graph/default_graph.hpp)
    bool key_poses = false;      // --key-poses: a key-pose graph (app/cli/key_pose_commands.hpp)
    KeyPoseBuildOptions key_pose;
};

struct GraphInfoOptions {
    std::string graph_file;
    bool json = false;
};

struct GraphPathOptions {
    std::string graph_file;
    std::string from;
    std::string to;
    std::string bvh_file;
    std::string config_file;
    bool json = false;
};

double peak_rss_mb() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

std::string node_name(const MotionGraph& g, int node) {
    const GraphNode& n = g.nodes[static_cast<size_t>(node)];
    return g.clips[static_cast<size_t>(n.clip)].name + ":" + std::to_string(n.frame);
}

std::string label_names(const MotionGraph& g, std::uint32_t mask) {
    std::string out;
    for (size_t l = 0; l < g.labels.size(); ++l)
        if (mask & (1u << l)) out += (out.empty() ? "" : ",") + json::quote(g.labels[l]);
    return "[" + out + "]";
}

void write_plot(const std::string& path, const offline::GraphBuildOutput& out) {
    const int size = out.plot_size;
    const std::int64_t n = out.frames;
    std::vector<unsigned char> rgb(static_cast<size_t>(size) * static_cast<size_t>(size) * 3, 0);  // RGB, then RGBA
    // Brightness falls with distance (scaled by 8× the threshold): bright = similar.
    const double scale = std::max(out.threshold * 8.0, 1e-12);
    for (int x = 0; x < size; ++x)
        for (int y = 0; y < size; ++y) {
            const float d = out.plot[static_cast<size_t>(x) * static_cast<size_t>(size) + static_cast<size_t>(y)];
            unsigned char v = 0;
            if (d >= 0.0f && d < offline::kPairInvalid) v = static_cast<unsigned char>(255.0 * std::exp(-d / scale));
            unsigned char* px = &rgb[(static_cast<size_t>(x) * static_cast<size_t>(size) + static_cast<size_t>(y)) * 3];
            px[0] = px[1] = px[2] = v;
        }
    // Rows are frame i (source), columns frame j (target). Candidates red, kept transitions green.
    std::set<std::pair<std::int32_t, std::int32_t>> kept;
    const MotionGraph& g = out.graph;
    for (const GraphEdge& e : g.edges)
        if (e.kind == GraphEdgeKind::transition) {
            const GraphNode& a = g.nodes[static_cast<size_t>(e.from)];
            const GraphNode& b = g.nodes[static_cast<size_t>(e.to)];
            kept.insert({g.clips[static_cast<size_t>(a.clip)].first_frame + a.frame,
                         g.clips[static_cast<size_t>(b.clip)].first_frame + b.frame - 1});
        }
    for (const offline::TransitionCandidate& c : out.candidates) {
        const bool is_kept = kept.count({c.from_frame, c.to_frame}) > 0;
        const int x = static_cast<int>(c.from_frame * size / n), y = static_cast<int>(c.to_frame * size / n);
        for (int dx = -1; dx <= 1; ++dx)
            for (int dy = -1; dy <= 1; ++dy) {
                const int px = x + dx, py = y + dy;
                if (px < 0 || py < 0 || px >= size || py >= size) continue;
                unsigned char* p = &rgb[(static_cast<size_t>(px) * static_cast<size_t>(size) + static_cast<size_t>(py)) * 3];
                p[0] = is_kept ? 0 : 255;
                p[1] = is_kept ? 255 : 0;
                p[2] = 0;
            }
    }
    // One PNG writer in the project (render_es/image.hpp, stb_image_write).
    render::Image image;
    image.width = size;
    image.height = size;
    image.rgba.resize(static_cast<size_t>(size) * static_cast<size_t>(size) * 4);
    for (size_t i = 0, n_px = static_cast<size_t>(size) * static_cast<size_t>(size); i < n_px; ++i) {
        image.rgba[i * 4 + 0] = rgb[i * 3 + 0];
        image.rgba[i * 4 + 1] = rgb[i * 3 + 1];
        image.rgba[i * 4 + 2] = rgb[i * 3 + 2];
        image.rgba[i * 4 + 3] = 255;
    }
    render::write_png(path, image);
}

std::string dot_text(const MotionGraph& g) {
    std::string out = "digraph motion_graph {\n  rankdir=LR;\n  node [shape=box, fontsize=10];\n";
    for (size_t n = 0; n < g.nodes.size(); ++n)
        out += fmt::format("  n{} [label=\"{}\"];\n", n, node_name(g, static_cast<int>(n)));
    for (const GraphEdge& e : g.edges) {
        if (e.kind == GraphEdgeKind::clip)
            out += fmt::format("  n{} -> n{} [label=\"{} f\", penwidth=2];\n", e.from, e.to, e.frames);
        else
            out += fmt::format("  n{} -> n{} [label=\"{:.3g}\", style=dashed, color=blue];\n", e.from, e.to, e.cost);
    }
    return out + "}\n";
}

// CLIP:FRAME → (clip index, frame), or throws naming what was wrong.
std::pair<int, int> parse_clip_frame(const MotionGraph& g, const std::string& text, const std::string& option) {
    const size_t colon = text.find_last_of(':');
    if (colon == std::string::npos) return {-1, -1};
    const std::string name = text.substr(0, colon);
    const int clip = g.clip_index(name);
    std::string known;
    for (const GraphClip& c : g.clips) known += (known.empty() ? "" : ", ") + c.name;
    if (clip < 0) throw ImportError(option, 0, "no clip named '" + name + "' in the graph (clips: " + known + ")");
    int frame = -1;
    try {
        size_t used = 0;
        frame = std::stoi(text.substr(colon + 1), &used);
        if (used != text.size() - colon - 1) frame = -1;
    } catch (const std::exception&) {
        frame = -1;
    }
    const int count = g.clips[static_cast<size_t>(clip)].frame_count;
    if (frame < 0 || frame >= count)
        throw ImportError(option, 0, "'" + text + "': expected a 0-based frame index 0.." + std::to_string(count - 1) +
                                         " after the clip name (frames at the graph's " +
                                         fmt::format("{}", g.frame_rate) + " Hz)");
    return {clip, frame};
}

std::string kept_range(const MotionGraph& g, int clip) {
    int lo = -1, hi = -1;
    for (const GraphEdge& e : g.edges) {
        if (e.kind != GraphEdgeKind::clip) continue;
        const GraphNode& a = g.nodes[static_cast<size_t>(e.from)];
        const GraphNode& b = g.nodes[static_cast<size_t>(e.to)];
        if (a.clip != clip) continue;
        lo = lo < 0 ? a.frame : std::min(lo, a.frame);
        hi = std::max(hi, b.frame);
    }
    return lo < 0 ? std::string("none of its frames is kept") : fmt::format("kept frames lie in {}..{}", lo, hi);
}

}  // namespace

// `graph build --default`: the embedded default graph, exported for inspection.
int graph_default_build_command(const GraphBuildCommandOptions& o) {
    if (!o.clip_files.empty() || !o.asf_file.empty() || !o.labels_file.empty())
        throw ImportError("command line", 0, "--default builds the embedded clips: give no CLIPS, --asf or --labels with it");
    const AppConfig config = load_config(o.config_file);
    offline::GraphBuildHooks hooks;
    if (!o.plot_file.empty()) hooks.plot_size = 1024;
    const DefaultGraphBuild build = build_default_motion_graph_report(config.sim, config.graph_build, hooks, o.threads);
    const offline::GraphBuildOutput& out = build.output;
    const MotionGraph& g = out.graph;
    write_binary_file(o.output_file, serialize_motion_graph(g));
    if (!o.plot_file.empty()) write_plot(o.plot_file, out);
    if (!o.dot_file.empty()) write_text_file(o.dot_file, dot_text(g));
    const double kept_pct = out.frames > 0 ? 100.0 * static_cast<double>(g.stats.frames_kept) / out.frames : 0.0;
    const std::vector<std::string> kept = kept_clip_names(g);
    std::string labels_kept;
    for (const LabelReachability& l : out.prune.labels)
        if (l.clips_kept > 0) labels_kept += (labels_kept.empty() ? "" : ",") + json::quote(l.label);
    if (o.json) {
        std::string clips;
        for (const std::string& c : kept) clips += (clips.empty() ? "" : ",") + json::quote(c);
        fmt::print("{{\"output\":{},\"default\":true,\"clips\":{},\"frames\":{},\"candidates\":{},\"bridges\":{},"
                   "\"nodes_before\":{},\"edges_before\":{},\"nodes\":{},\"edges\":{},\"frames_kept_pct\":{},"
                   "\"clips_kept\":[{}],\"labels_kept\":[{}],\"source_hash\":\"{:016x}\",\"build_ms\":{},\"build_seconds\":{},"
                   "\"peak_rss_mb\":{}}}\n",
                   json::quote(o.output_file), build.clips, out.frames, out.regular_candidates, out.bridges,
                   out.prune.nodes_before, out.prune.edges_before, out.prune.nodes, out.prune.edges,
                   json::number(kept_pct), clips, labels_kept, g.source_hash, json::number(build.build_ms),
                   json::number(build.build_ms / 1000.0), json::number(peak_rss_mb()));
    } else {
        fmt::print("default graph: {} clips, {} frames, {} candidate transitions, {} bridges\n", build.clips, out.frames,
                   out.regular_candidates, out.bridges);
        fmt::print("graph {} nodes / {} edges → {} nodes / {} edges, {:.1f}% of frames kept\n", out.prune.nodes_before,
                   out.prune.edges_before, out.prune.nodes, out.prune.edges, kept_pct);
        fmt::print("clips kept: {}\nwrote {} in {:.0f} ms\n", fmt::join(kept, " "), o.output_file, build.build_ms);
    }
    return 0;
}

int graph_build_command(const GraphBuildCommandOptions& o) {
    if (o.default_graph) return graph_default_build_command(o);
    if (o.key_poses || !o.key_pose.from_xml.empty()) {
        KeyPoseBuildOptions k = o.key_pose;
        k.asf_file = o.asf_file;
        k.clip_files = o.clip_files;
        k.labels_file = o.labels_file;
        k.config_file = o.config_file;
        k.output_file = o.output_file;
        k.keep_skeleton = o.keep_skeleton;
        k.json = o.json;
        return key_pose_build_command(k);
    }
    if (o.clip_files.empty())
        throw ImportError("command line", 0, "graph build needs CLIPS (.bvh, or .amc with --asf), or --default");
    const AppConfig app_config = load_config(o.config_file);
    const GraphBuildConfig& build_config = app_config.graph_build;
    const GraphSources sources{o.asf_file, o.clip_files, o.labels_file};
    offline::GraphBuildParams params = graph_build_params(build_config);
    params.threads = o.threads;
    const auto started = std::chrono::steady_clock::now();
    // Clips of any humanoid skeleton are retargeted onto the puppet as they load.
    const Skeleton puppet = make_puppet_skeleton(app_config.sim);
    const offline::ClipDatabase db = load_graph_sources(sources, params.analysis_rate_hz, o.keep_skeleton ? nullptr : &puppet);

    offline::GraphBuildHooks hooks;
    const bool bar = isatty(fileno(stderr)) != 0;
    if (bar)
        hooks.progress = [](double f) {
            const int width = 40, filled = static_cast<int>(f * width + 0.5);
            fmt::print(stderr, "\rdistances [{}{}] {:3.0f}%", std::string(static_cast<size_t>(filled), '#'),
                       std::string(static_cast<size_t>(width - filled), ' '), f * 100.0);
            if (f >= 1.0) fmt::print(stderr, "\n");
            std::fflush(stderr);
        };
    if (!o.plot_file.empty()) hooks.plot_size = 1024;
    offline::GraphBuildOutput out = build_graph_from_sources(db, sources, params, hooks);
    MotionGraph& g = out.graph;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    if (g.nodes.empty())
        throw std::runtime_error(fmt::format(
            "no strongly connected component: {} candidate transitions at threshold {:.4g} leave no cycle "
            "(raise motion_graph.threshold_percentile)",
            out.candidates.size(), out.threshold));
    // build_seconds stays 0 in the file (same build, same bytes); --json reports it.
    write_binary_file_atomically(o.output_file, serialize_motion_graph(g));
    if (!o.plot_file.empty()) write_plot(o.plot_file, out);
    if (!o.dot_file.empty()) write_text_file(o.dot_file, dot_text(g));

    const double kept_pct = out.frames > 0 ? 100.0 * static_cast<double>(g.stats.frames_kept) / out.frames : 0.0;
    const std::vector<std::string> kept = kept_clip_names(g);
    if (o.json) {
        std::string clips, labels;
        for (const std::string& c : kept) clips += (clips.empty() ? "" : ",") + json::quote(c);
        for (const LabelReachability& l : out.prune.labels)
            labels += fmt::format("{}{{\"label\":{},\"clips\":{},\"clips_kept\":{},\"reachable\":{},\"reason\":{}}}",
                                  labels.empty() ? "" : ",", json::quote(l.label), l.clips, l.clips_kept,
                                  l.clips_kept > 0 ? "true" : "false", l.reason.empty() ? "null" : json::quote(l.reason));
        fmt::print("{{\"output\":{},\"clips\":{},\"frames\":{},\"analysis_rate_hz\":{},\"pair_evaluations\":{},"
                   "\"threshold\":{},\"bridge_threshold\":{},\"bridges\":{},\"candidates\":{},\"nodes_before\":{},\"edges_before\":{},\"nodes\":{},\"edges\":{},"
                   "\"frames_kept_pct\":{},\"clips_kept\":[{}],\"labels\":[{}],\"build_seconds\":{},\"peak_rss_mb\":{}}}\n",
                   json::quote(o.output_file), db.clips.size(), out.frames, json::number(params.analysis_rate_hz),
                   g.stats.pair_evaluations, json::number(out.threshold), json::number(out.bridge_threshold), out.bridges,
                   out.regular_candidates, out.prune.nodes_before,
                   out.prune.edges_before, out.prune.nodes, out.prune.edges, json::number(kept_pct), clips, labels,
                   json::number(seconds), json::number(peak_rss_mb()));
    } else {
        fmt::print("{} clips, {} frames at {} Hz: {} pair distances, threshold {:.4g}, {} candidate transitions, "
                   "{} bridges (below {:.4g}) into cut-off clips\n",
                   db.clips.size(), out.frames, params.analysis_rate_hz, g.stats.pair_evaluations, out.threshold,
                   out.regular_candidates, out.bridges, out.bridge_threshold);
        fmt::print("graph {} nodes / {} edges → largest component {} nodes / {} edges, {:.1f}% of frames kept\n",
                   out.prune.nodes_before, out.prune.edges_before, out.prune.nodes, out.prune.edges, kept_pct);
        fmt::print("clips kept: {}\n", fmt::join(kept, " "));
        for (const LabelReachability& l : out.prune.labels)
            if (!l.reason.empty()) fmt::print("label '{}' cut off: {}\n", l.label, l.reason);
        fmt::print("wrote {} in {:.2f} s (peak RSS {:.0f} MB)\n", o.output_file, seconds, peak_rss_mb());
    }
    return 0;
}

int graph_info_command(const GraphInfoOptions& o) {
    const auto t0 = std::chrono::steady_clock::now();
    const MotionGraph g = load_motion_graph_file(o.graph_file);
    const double load_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    int transitions = 0;
    // The transitions' registration (transition_time_warp): DTW path costs
    // summed over every transition, warped against the plain blend's diagonal.
    double warped = 0.0, diagonal = 0.0;
    const bool warps = transition_warps_affordable(g);
    for (const GraphEdge& e : g.edges) {
        transitions += e.kind == GraphEdgeKind::transition;
        double w = 0.0, d = 0.0;
        if (warps) transition_warp_costs(g, e, w, d);
        warped += w, diagonal += d;
    }
    const double warp_ratio = diagonal > 0.0 ? warped / diagonal : 1.0;  // 1: not warped
    const std::vector<std::string> kept = kept_clip_names(g);
    if (o.json) {
        std::string clips, labels, kept_json;
        for (const GraphClip& c : g.clips)
            clips += fmt::format("{}{{\"name\":{},\"frames\":{},\"labels\":{},\"kept\":{}}}", clips.empty() ? "" : ",",
                                 json::quote(c.name), c.frame_count, label_names(g, c.label_mask),
                                 std::find(kept.begin(), kept.end(), c.name) != kept.end() ? "true" : "false");
        for (const std::string& l : g.labels) labels += (labels.empty() ? "" : ",") + json::quote(l);
        for (const std::string& c : kept) kept_json += (kept_json.empty() ? "" : ",") + json::quote(c);
        fmt::print("{{\"file\":{},\"version\":{},\"source_hash\":\"{:016x}\",\"joints\":{},\"frame_rate\":{},"
                   "\"window_frames\":{},\"frames\":{},\"nodes\":{},\"edges\":{},\"transitions\":{},"
                   "\"nodes_before\":{},\"edges_before\":{},\"candidates\":{},\"threshold\":{},\"frames_kept_pct\":{},"
                   "\"labels\":[{}],\"clips_kept\":[{}],\"clips\":[{}],\"transition_warp_cost_ratio\":{},\"load_ms\":{}}}\n",
                   json::quote(o.graph_file), kMotionGraphVersion, g.source_hash, g.joint_count(),
                   json::number(g.frame_rate), g.window_frames, g.contacts.size(), g.nodes.size(), g.edges.size(),
                   transitions, g.stats.nodes_before, g.stats.edges_before, g.stats.candidates,
                   json::number(g.stats.threshold),
                   json::number(g.stats.frames > 0 ? 100.0 * static_cast<double>(g.stats.frames_kept) / g.stats.frames : 0.0),
                   labels, kept_json, clips, json::number(warp_ratio), json::number(load_ms));
    } else {
        fmt::print("{}: motion graph v{}, {} joints, {} frames at {} Hz, k = {}\n", o.graph_file, kMotionGraphVersion,
                   g.joint_count(), g.contacts.size(), g.frame_rate, g.window_frames);
        fmt::print("{} nodes, {} edges ({} transitions); before pruning {} nodes, {} edges\n", g.nodes.size(),
                   g.edges.size(), transitions, g.stats.nodes_before, g.stats.edges_before);
        if (warps)
            fmt::print("transitions registered by time warping: pose distance {:.1f} % of the plain blend's\n",
                       100.0 * warp_ratio);
        else
            fmt::print("transitions not time-warped (window over {} frames, or too many transitions × joints)\n",
                       kMaxWarpWindowFrames);
        fmt::print("labels: {}\nclips kept: {}\nloaded in {:.2f} ms\n", fmt::join(g.labels, " "), fmt::join(kept, " "),
                   load_ms);
    }
    return 0;
}

int graph_path_command(const GraphPathOptions& o) {
    if (is_key_pose_graph_file(o.graph_file))
        return key_pose_path_command({o.graph_file, o.from, o.to, o.bvh_file, o.json});
    const SimConfig config = load_config(o.config_file).sim;
    const MotionGraph g = load_motion_graph_file(o.graph_file);
    const auto [from_clip, from_frame] = parse_clip_frame(g, o.from, "--from");
    if (from_clip < 0) throw ImportError("--from", 0, "'" + o.from + "': expected CLIP:FRAME");
    GraphLocation start = locate_frame(g, from_clip, from_frame);
    if (start.node < 0) {
        // Before the clip's kept part: the clip plays forward until it enters the graph.
        for (size_t n = 0; n < g.nodes.size(); ++n)
            if (g.nodes[n].clip == from_clip && g.nodes[n].frame > from_frame &&
                (start.node < 0 || g.nodes[n].frame < g.nodes[static_cast<size_t>(start.node)].frame))
                start.node = static_cast<std::int32_t>(n);
        if (start.node < 0)
            throw ImportError("--from", 0, "'" + o.from + "' lies after the part of its clip in the pruned graph (" +
                                               kept_range(g, from_clip) + ")");
        start.frames_after = from_frame - g.nodes[static_cast<size_t>(start.node)].frame;  // negative: frames before
    }
    GraphPathSearch search(g, config.graph_transition_weight);
    const auto [to_clip, to_frame] = parse_clip_frame(g, o.to, "--to");
    if (to_clip >= 0) {
        if (!search.add_frame_goal(to_clip, to_frame))
            throw ImportError("--to", 0, "'" + o.to + "' is not in the pruned graph (" + kept_range(g, to_clip) + ")");
    } else {
        const int label = g.label_index(o.to);
        if (label < 0)
            throw ImportError("--to", 0, "'" + o.to + "' is neither CLIP:FRAME nor a label of the graph (labels: " +
                                             fmt::format("{}", fmt::join(g.labels, ", ")) + ")");
        search.add_label_goal(label);
    }
    // Start: play from the frame up to the next node, where the search begins. The
    // node at or before the frame is where its clip edge starts; the search starts
    // at that edge's end unless the frame is the node itself.
    int start_node = start.node;
    int lead_frames = -std::min(start.frames_after, 0);
    if (start.frames_after > 0) {
        for (const GraphEdge& e : g.out_edges(start.node))
            if (e.kind == GraphEdgeKind::clip) {
                start_node = e.to;
                lead_frames = e.frames - start.frames_after;
            }
    }
    const auto t0 = std::chrono::steady_clock::now();
    const bool found = search.run(start_node);
    const double micros = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
    if (!found) {
        log_message(LogLevel::error, fmt::format("error: no path from {} to {} in the pruned graph", o.from, o.to));
        return 1;
    }
    const double cost = search.cost() + lead_frames / g.frame_rate;
    const std::span<const std::int32_t> path = search.path();
    // The sequence: (clip, first frame, last frame) runs, transitions between them.
    std::string steps;
    int frames = lead_frames;
    int clip = from_clip, first = from_frame;
    int frame = g.nodes[static_cast<size_t>(start_node)].frame;
    const auto add_run = [&](int c, int a, int b) {
        if (b < a) return;
        steps += fmt::format("{}{{\"clip\":{},\"from\":{},\"to\":{}}}", steps.empty() ? "" : ",",
                             json::quote(g.clips[static_cast<size_t>(c)].name), a, b);
    };
    int transitions = 0;
    for (const std::int32_t ei : path) {
        const GraphEdge& e = g.edges[static_cast<size_t>(ei)];
        frames += e.frames;
        const GraphNode& a = g.nodes[static_cast<size_t>(e.from)];
        if (e.kind == GraphEdgeKind::clip) {
            frame = a.frame + e.frames;
            continue;
        }
        add_run(clip, first, a.frame + g.window_frames - 1);
        const GraphNode& b = g.nodes[static_cast<size_t>(e.to)];
        steps += fmt::format(",{{\"transition\":{{\"from\":{},\"to\":{},\"cost\":{}}}}}", json::quote(node_name(g, e.from)),
                             json::quote(node_name(g, e.to)), json::number(e.cost));
        ++transitions;
        clip = b.clip;
        first = b.frame - g.window_frames;
        frame = b.frame;
    }
    const int last = frame + search.goal_frames_after();
    add_run(clip, first, last);
    if (!o.bvh_file.empty()) {
        Clip motion = synthesize_path(g, from_clip, from_frame,
                                      std::vector<std::int32_t>(path.begin(), path.end()), search.goal_frames_after());
        write_text_file(o.bvh_file, export_bvh(motion));
    }
    if (o.json) {
        fmt::print("{{\"from\":{},\"to\":{},\"found\":true,\"cost\":{},\"frames\":{},\"seconds\":{},\"transitions\":{},"
                   "\"sequence\":[{}],\"search_us\":{},\"settled_nodes\":{}}}\n",
                   json::quote(o.from), json::quote(o.to), json::number(cost), frames + search.goal_frames_after() + 1,
                   json::number((frames + search.goal_frames_after()) / g.frame_rate), transitions, steps,
                   json::number(micros), search.settled_nodes());
    } else {
        fmt::print("path {} → {}: cost {:.4f}, {} transitions, {:.2f} s of motion, found in {:.1f} µs\n", o.from, o.to,
                   cost, transitions, (frames + search.goal_frames_after()) / g.frame_rate, micros);
        fmt::print("[{}]\n", steps);
    }
    return 0;
}

void register_graph_commands(CLI::App& app, int& exit_code) {
    CLI::App* graph = app.add_subcommand("graph", "Build, inspect and search motion graphs");
    graph->require_subcommand(1);

    auto b = std::make_shared<GraphBuildCommandOptions>();
    CLI::App* build = graph->add_subcommand("build", "Build a motion graph from BVH or ASF/AMC clips");
    build->add_option("--asf", b->asf_file, "skeleton for AMC clips")->check(CLI::ExistingFile);
    build->add_option("clips", b->clip_files, "clip files (.bvh, or .amc with --asf)");
    build->add_flag("--keep-skeleton", b->keep_skeleton,
                    "keep the clips' own skeleton (one shared skeleton) instead of retargeting them onto the puppet");
    build->add_flag("--default", b->default_graph, "build the embedded default graph (project clips + gait locomotion)");
    build->add_option("-o,--output", b->output_file, "the .mgraph file to write")->required();
    build->add_option("--labels", b->labels_file, "labels file (TOML; default config/graph_labels.toml)")
        ->check(CLI::ExistingFile);
    build->add_option("--config", b->config_file, "TOML file overriding the [motion_graph] defaults")
        ->check(CLI::ExistingFile);
    build->add_option("--plot", b->plot_file, "write the distance matrix with transitions marked as PNG");
    build->add_option("--dot", b->dot_file, "write the pruned graph for Graphviz");
    build->add_option("--threads", b->threads, "worker threads (0: all cores)")->check(CLI::Range(0, 256));
    build->add_flag("--json", b->json, "print a JSON summary");
    build->add_flag("--key-poses", b->key_poses,
                    "build a key-pose graph (speed minima, thinned, linked by pose difference), written as XML");
    build->add_option("--from-xml", b->key_pose.from_xml, "read a key-pose graph from XML (and write it to -o)")
        ->check(CLI::ExistingFile);
    build->add_option("--thin", b->key_pose.thin, "key poses: no two closer than this pose difference (leg lengths²; 0: percentile)")
        ->check(CLI::Range(0.0, 1e9));
    build->add_option("--link", b->key_pose.link, "key poses: link poses closer than this (leg lengths²; 0: percentile)")
        ->check(CLI::Range(0.0, 1e9));
    build->add_option("--thin-percentile", b->key_pose.thin_percentile, "key poses: --thin as this percentile of minima pairs")
        ->check(CLI::Range(0.0, 100.0));
    build->add_option("--link-percentile", b->key_pose.link_percentile, "key poses: --link as this percentile of minima pairs")
        ->check(CLI::Range(0.0, 100.0));
    on_parsed(build, exit_code, [b] { return graph_build_command(*b); });

    auto i = std::make_shared<GraphInfoOptions>();
    CLI::App* info = graph->add_subcommand("info", "Summarise a .mgraph file");
    info->add_option("graph", i->graph_file, ".mgraph file")->required();
    info->add_flag("--json", i->json, "print JSON");
    on_parsed(info, exit_code, [i] { return graph_info_command(*i); });

    auto p = std::make_shared<GraphPathOptions>();
    CLI::App* path = graph->add_subcommand("path", "Cheapest path from a clip frame to a label or clip frame");
    path->add_option("graph", p->graph_file, ".mgraph file")->required();
    path->add_option("--from", p->from, "CLIP:FRAME (0-based frame at the graph's rate); on a key-pose graph a pose id or CLIP:FRAME")->required();
    path->add_option("--to", p->to, "LABEL or CLIP:FRAME; on a key-pose graph a pose id or CLIP:FRAME")->required();
    path->add_option("--bvh", p->bvh_file, "write the synthesised motion along the path as BVH");
    path->add_option("--config", p->config_file, "TOML file overriding the defaults")->check(CLI::ExistingFile);
    path->add_flag("--json", p->json, "print JSON");
    on_parsed(path, exit_code, [p] { return graph_path_command(*p); });

    auto x = std::make_shared<std::pair<std::string, std::string>>();
    CLI::App* xport = graph->add_subcommand("export", "Write a key-pose graph as XML");
    xport->add_option("graph", x->first, "key-pose graph file")->required()->check(CLI::ExistingFile);
    xport->add_option("--xml", x->second, "the XML file to write")->required();
    on_parsed(xport, exit_code, [x] { return key_pose_export_command(x->first, x->second); });
}

}  // namespace marionette
