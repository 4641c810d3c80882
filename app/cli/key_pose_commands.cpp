// `graph build --key-poses | --from-xml`, `graph path` and `graph export --xml` on
// key-pose graphs (docs/motion-graph.md, "Key-pose graphs").
#include "app/cli/key_pose_commands.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <fstream>

#include "app/config/config.hpp"
#include "app/graph/graph_files.hpp"
#include "app/graph/graph_rebuild.hpp"
#include "app/io/files.hpp"
#include "app/io/json.hpp"
#include "app/io/log.hpp"
#include "graph_builder/key_pose_xml.hpp"
#include "runtime/errors/import_error.hpp"
#include "runtime/formats/bvh.hpp"
#include "runtime/gait/puppet.hpp"

namespace marionette {

namespace {

offline::KeyPoseGraph load_key_pose_graph(const std::string& path) {
    const std::string text = read_text_file(path);
    if (text.rfind("MGRAPH", 0) == 0)
        throw ImportError(path, 0, "this is a .mgraph motion graph; key-pose commands read a key-pose graph "
                                   "(XML, written by graph build --key-poses)");
    return offline::parse_key_pose_xml(text, path);
}

// A pose id, or CLIP:FRAME (the key pose of that clip nearest the frame, the earlier on a tie).
int parse_pose(const offline::KeyPoseGraph& g, const std::string& text, const std::string& option) {
    const int n = static_cast<int>(g.poses.size());
    if (n == 0) throw ImportError(option, 0, "the graph has no key poses to start or end at");
    const size_t colon = text.find_last_of(':');
    if (colon == std::string::npos) {
        int id = -1;
        size_t used = 0;
        try {
            id = std::stoi(text, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used == 0 || used != text.size())
            throw ImportError(option, 0, "'" + text + "': expected a key-pose id (0.." + std::to_string(n - 1) + ") or CLIP:FRAME");
        if (id < 0 || id >= n)
            throw ImportError(option, 0, "unknown key-pose id " + text + ": the graph has poses 0.." + std::to_string(n - 1));
        return id;
    }
    const std::string clip = text.substr(0, colon);
    int frame = -1;
    try {
        size_t used = 0;
        frame = std::stoi(text.substr(colon + 1), &used);
        if (used != text.size() - colon - 1) frame = -1;
    } catch (const std::exception&) {
        frame = -1;
    }
    if (frame < 0) throw ImportError(option, 0, "'" + text + "': expected a 0-based frame index after the clip name");
    int best = -1;
    std::string clips;
    for (int p = 0; p < n; ++p) {
        const offline::KeyPose& k = g.poses[static_cast<size_t>(p)];
        if (clips.find(" " + k.clip + ",") == std::string::npos) clips += " " + k.clip + ",";
        if (k.clip != clip) continue;
        if (best < 0 || std::abs(k.frame - frame) < std::abs(g.poses[static_cast<size_t>(best)].frame - frame)) best = p;
    }
    if (best < 0) {
        if (!clips.empty()) clips.pop_back();
        throw ImportError(option, 0, "no key pose of a clip named '" + clip + "' (clips with key poses:" + clips + ")");
    }
    return best;
}

std::string pose_name(const offline::KeyPoseGraph& g, int p) {
    const offline::KeyPose& k = g.poses[static_cast<size_t>(p)];
    return fmt::format("{} ({}:{})", p, k.clip, k.frame);
}

}  // namespace

bool is_key_pose_graph_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    char c = 0;
    while (in.get(c))
        if (c != ' ' && c != '\t' && c != '\r' && c != '\n') return c == '<';
    return false;
}

int key_pose_build_command(const KeyPoseBuildOptions& o) {
    const auto started = std::chrono::steady_clock::now();
    offline::KeyPoseGraph g;
    offline::KeyPoseBuildReport report;
    if (!o.from_xml.empty()) {
        if (!o.clip_files.empty()) throw ImportError("command line", 0, "--from-xml reads the graph from the file: give no CLIPS with it");
        g = offline::parse_key_pose_xml(read_text_file(o.from_xml), o.from_xml);
    } else {
        if (o.clip_files.empty())
            throw ImportError("command line", 0, "graph build --key-poses needs CLIPS (.bvh, or .amc with --asf)");
        const AppConfig config = load_config(o.config_file);
        const double rate = graph_build_params(config.graph_build).analysis_rate_hz;
        const Skeleton puppet = make_puppet_skeleton(config.sim);
        const offline::ClipDatabase db =
            load_graph_sources({o.asf_file, o.clip_files, o.labels_file}, rate, o.keep_skeleton ? nullptr : &puppet);
        offline::KeyPoseParams params;
        params.thin_threshold = o.thin;
        params.link_threshold = o.link;
        params.thin_percentile = o.thin_percentile;
        params.link_percentile = o.link_percentile;
        try {
            g = offline::build_key_pose_graph(db, params, &report);
        } catch (const std::invalid_argument& e) {
            throw ImportError("--key-poses", 0, e.what());
        }
    }
    write_text_file(o.output_file, offline::write_key_pose_xml(g));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    const std::vector<std::int32_t> comp = offline::key_pose_components(g);
    std::vector<std::int64_t> sizes(comp.size(), 0);
    for (std::int32_t c : comp) ++sizes[static_cast<size_t>(c)];
    const std::int64_t components = std::count_if(sizes.begin(), sizes.end(), [](std::int64_t s) { return s > 0; });
    const std::int64_t largest = sizes.empty() ? 0 : *std::max_element(sizes.begin(), sizes.end());
    if (o.json) {
        fmt::print("{{\"output\":{},\"frames\":{},\"minima\":{},\"key_poses\":{},\"edges\":{},\"components\":{},"
                   "\"largest_component\":{},\"thin_threshold\":{},\"link_threshold\":{},\"step\":{},\"build_seconds\":{}}}\n",
                   json::quote(o.output_file), report.frames, report.minima, g.poses.size(), g.edges.size(), components,
                   largest, json::number(g.thin_threshold), json::number(g.link_threshold), json::number(g.step),
                   json::number(seconds));
    } else {
        if (o.from_xml.empty())
            fmt::print("{} frames: {} speed minima → {} key poses (none closer than {:.4g}), ", report.frames, report.minima,
                       g.poses.size(), g.thin_threshold);
        else
            fmt::print("{}: {} key poses, ", o.from_xml, g.poses.size());
        fmt::print("{} edges below {:.4g}, {} components (largest {} poses)\nwrote {} in {:.2f} s\n", g.edges.size(),
                   g.link_threshold, components, largest, o.output_file, seconds);
    }
    return 0;
}

int key_pose_path_command(const KeyPosePathOptions& o) {
    const offline::KeyPoseGraph g = load_key_pose_graph(o.graph_file);
    const int from = parse_pose(g, o.from, "--from"), to = parse_pose(g, o.to, "--to");
    const auto t0 = std::chrono::steady_clock::now();
    double cost = 0.0;
    const std::vector<std::int32_t> path = offline::key_pose_path(g, from, to, &cost);
    const double micros = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
    if (path.empty()) {
        log_message(LogLevel::error, fmt::format("error: no path from key pose {} to key pose {}: they lie in different "
                                                 "components of the graph (raise --link or --link-percentile)",
                                                 pose_name(g, from), pose_name(g, to)));
        return 1;
    }
    const Clip motion = offline::synthesize_key_pose_path(g, path);
    if (!o.bvh_file.empty()) write_text_file(o.bvh_file, export_bvh(motion));
    const offline::PopStats pops = offline::clip_pop_stats(motion);
    const double ratio = pops.p95 > 0.0 ? pops.largest / pops.p95 : 0.0;
    std::string poses;
    for (const std::int32_t p : path) {
        const offline::KeyPose& k = g.poses[static_cast<size_t>(p)];
        poses += fmt::format("{}{{\"id\":{},\"clip\":{},\"frame\":{}}}", poses.empty() ? "" : ",", p, json::quote(k.clip), k.frame);
    }
    if (o.json) {
        fmt::print("{{\"from\":{},\"to\":{},\"found\":true,\"cost\":{},\"poses\":[{}],\"frames\":{},\"seconds\":{},"
                   "\"largest_move\":{},\"p95_move\":{},\"pop_ratio\":{},\"search_us\":{}}}\n",
                   from, to, json::number(cost), poses, motion.frame_count, json::number(motion.duration()),
                   json::number(pops.largest), json::number(pops.p95), json::number(ratio), json::number(micros));
    } else {
        fmt::print("path {} → {}: cost {:.4g}, {} key poses, {} frames ({:.2f} s), found in {:.1f} µs\n", pose_name(g, from),
                   pose_name(g, to), cost, path.size(), motion.frame_count, motion.duration(), micros);
        fmt::print("largest per-frame joint move {:.3g}, 95th percentile {:.3g} (ratio {:.2f})\n[{}]\n", pops.largest,
                   pops.p95, ratio, poses);
    }
    return 0;
}

int key_pose_export_command(const std::string& graph_file, const std::string& xml_file) {
    const offline::KeyPoseGraph g = load_key_pose_graph(graph_file);
    write_text_file(xml_file, offline::write_key_pose_xml(g));
    fmt::print("wrote {}: {} key poses, {} edges\n", xml_file, g.poses.size(), g.edges.size());
    return 0;
}

}  // namespace marionette
