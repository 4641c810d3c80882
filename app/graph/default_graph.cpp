// The embedded default motion graph (app/graph/default_graph.hpp).
#include "app/graph/default_graph.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "app/config/embedded.hpp"
#include "app/graph/graph_files.hpp"
#include "graph_builder/clip_database.hpp"
#include "runtime/formats/bvh.hpp"
#include "runtime/sim/simulation.hpp"
#include "runtime/formats/stick_program.hpp"

namespace marionette {

namespace {

// One locomotion capture: a stick program, and the part of it kept as the clip
// (skipping the warm-up of steady clips so their label fits every frame).
struct LocomotionProgram {
    const char* name;  // matched by config/graph_labels.toml's patterns
    const char* program;
    double keep_from_s;
};

// Stick conventions (runtime/formats/stick_program.hpp): ly up walks toward −Z, but the
// puppet starts facing +Z, so the programs push the stick down (ly < 0): every clip
// then walks the way it faces from the start, and no start turns on the spot. A
// circle with positive turns sweeps the stick counter-clockwise (down → right here:
// toward +X, the puppet's left), so the puppet turns left.
const LocomotionProgram kLocomotion[] = {
    {"idle", "hold 4s\n", 0.0},
    {"walk_slow", "ramp 500ms ly=-0.35\nhold 4.5s\n", 2.0},
    {"walk", "ramp 500ms ly=-0.5\nhold 4.5s\n", 2.0},
    {"walk_brisk", "ramp 500ms ly=-0.7\nhold 4s\n", 2.0},
    {"run", "ramp 500ms ly=-1\nhold 4s\n", 2.0},
    {"walk_turn_left", "ramp 500ms ly=-0.5\nhold 1.5s\ncircle 3s radius=0.5 turns=0.25 from=270\nhold 1s\n", 1.5},
    {"walk_turn_right", "ramp 500ms ly=-0.5\nhold 1.5s\ncircle 3s radius=0.5 turns=-0.25 from=270\nhold 1s\n", 1.5},
    {"run_turn_left", "ramp 500ms ly=-1\nhold 1.5s\ncircle 2.5s radius=1 turns=0.25 from=270\nhold 1s\n", 1.5},
    {"run_turn_right", "ramp 500ms ly=-1\nhold 1.5s\ncircle 2.5s radius=1 turns=-0.25 from=270\nhold 1s\n", 1.5},
    // Start from standing and stop again: the idle ↔ walk/run links.
    {"idle_walk_stop", "hold 1s\nramp 500ms ly=-0.5\nhold 2.5s\nramp 300ms ly=0\nhold 2.5s\n", 0.0},
    {"idle_run_stop", "hold 1s\nramp 500ms ly=-1\nhold 2.5s\nramp 300ms ly=0\nhold 2.5s\n", 0.0},
    // Turns on the spot: from standing toward the puppet's back, left and right,
    // and a reversal while walking (the gait turns in place past turn_in_place_deg),
    // so the graph can head anywhere, not only where its clips happen to face.
    {"idle_turn_back_walk", "hold 1s\nramp 300ms ly=0.5\nhold 3s\nramp 300ms ly=0\nhold 1.5s\n", 0.0},
    {"idle_turn_left_walk", "hold 1s\nramp 300ms lx=0.5\nhold 3s\nramp 300ms lx=0\nhold 1.5s\n", 0.0},
    {"idle_turn_right_walk", "hold 1s\nramp 300ms lx=-0.5\nhold 3s\nramp 300ms lx=0\nhold 1.5s\n", 0.0},
    {"walk_turn_back", "ramp 500ms ly=-0.5\nhold 2s\nramp 200ms ly=0.5\nhold 3s\n", 1.0},
};

const char* const kActionPaths[] = {"config/clips/wave.bvh", "config/clips/bow.bvh", "config/clips/jump.bvh",
                                    "config/clips/look_around.bvh"};

Clip capture(const SimConfig& config, const LocomotionProgram& p, double rate_hz) {
    const StickProgram program = parse_stick_program(p.program, std::string("default graph program ") + p.name);
    const std::vector<TickInput> inputs = render_stick_program(program, config.tick_rate_hz);
    // Always on flat ground: the graph's clips are terrain-free (graph_feet adapts
    // them), and the default graph must not change with the configured terrain.
    Simulation sim(config, Terrain{});
    const Skeleton& skeleton = sim.skeleton();
    const int joints = skeleton.joint_count();
    const double tick_s = 1.0 / config.tick_rate_hz;
    Clip clip;
    clip.name = p.name;
    clip.skeleton = skeleton;
    clip.frame_rate = rate_hz;
    clip.animated_translation.assign(static_cast<size_t>(joints), false);
    for (int j = 0; j < joints; ++j)
        if (skeleton.parents[static_cast<size_t>(j)] == kNoParent) clip.animated_translation[static_cast<size_t>(j)] = true;
    // Frame f is the state after the tick that ends at keep_from + f / rate.
    int next_frame = 0;
    for (size_t k = 0; k < inputs.size(); ++k) {
        sim.step(inputs[k]);
        const double t = static_cast<double>(k + 1) * tick_s - p.keep_from_s;
        if (t + 0.5 * tick_s < next_frame / rate_hz) continue;
        const PuppetState& s = sim.state();
        for (int j = 0; j < joints; ++j) {
            clip.rotations.push_back(s.local_rotations[static_cast<size_t>(j)]);
            clip.translations.push_back(s.local_translations[static_cast<size_t>(j)]);
        }
        ++next_frame;
    }
    clip.frame_count = next_frame;
    return clip;
}

}  // namespace

const std::vector<std::string>& default_action_clip_names() {
    static const std::vector<std::string> names = {"wave", "bow", "jump", "look_around"};
    return names;
}

const std::vector<std::string>& default_graph_labels() {
    static const std::vector<std::string> labels = {"walk", "run",  "turn", "idle",       "stop",
                                                    "wave", "bow", "jump", "look_around"};
    return labels;
}

std::vector<Clip> default_action_clips() {
    std::vector<Clip> clips;
    for (const char* path : kActionPaths) {
        const std::string_view text = embedded::find(path);
        if (text.empty()) throw ImportError(path, 0, "embedded action clip missing from the binary");
        Clip clip = import_bvh(text, path);
        std::string name = path;
        name = name.substr(name.find_last_of('/') + 1);
        clip.name = name.substr(0, name.size() - 4);
        clips.push_back(std::move(clip));
    }
    return clips;
}

std::vector<Clip> generate_locomotion_clips(const SimConfig& config, double rate_hz) {
    std::vector<Clip> clips;
    for (const LocomotionProgram& p : kLocomotion) clips.push_back(capture(config, p, rate_hz));
    return clips;
}

DefaultGraphBuild build_default_motion_graph_report(const SimConfig& config, const GraphBuildConfig& build_config,
                                                    const offline::GraphBuildHooks& hooks, int threads) {
    const auto started = std::chrono::steady_clock::now();
    offline::GraphBuildParams params = graph_build_params(build_config);
    params.threads = threads;
    std::vector<Clip> clips = generate_locomotion_clips(config, params.analysis_rate_hz);
    for (Clip& c : default_action_clips()) clips.push_back(std::move(c));
    std::vector<std::string> names;
    for (const Clip& c : clips) names.push_back(c.name);
    const offline::LabelRules rules =
        offline::parse_label_rules(std::string(embedded::find("config/graph_labels.toml")), "config/graph_labels.toml");
    const offline::ClipDatabase db = offline::make_clip_database(std::move(clips), names, rules, params.analysis_rate_hz);

    DefaultGraphBuild build;
    build.clips = static_cast<int>(db.clips.size());
    build.output = offline::build_motion_graph(db, params, hooks);
    MotionGraph& g = build.output.graph;
    g.stats.build_seconds = 0.0;  // wall time would make the bytes differ run to run
    if (g.nodes.empty())
        throw std::runtime_error("default motion graph: no strongly connected component (raise motion_graph.threshold_percentile)");
    for (const std::string& label : default_graph_labels()) {
        const auto it = std::find_if(build.output.prune.labels.begin(), build.output.prune.labels.end(),
                                     [&](const LabelReachability& l) { return l.label == label; });
        if (it == build.output.prune.labels.end())
            throw std::runtime_error(fmt::format("default motion graph: no clip carries the label '{}'", label));
        if (it->clips_kept == 0)
            throw std::runtime_error(fmt::format("default motion graph: label '{}' cut off by pruning: {}", label,
                                                 it->reason.empty() ? "no clip of it in the component" : it->reason));
    }
    build.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started).count();
    return build;
}

MotionGraph build_default_motion_graph(const SimConfig& config, const GraphBuildConfig& build_config, int threads) {
    return std::move(build_default_motion_graph_report(config, build_config, {}, threads).output.graph);
}

}  // namespace marionette
