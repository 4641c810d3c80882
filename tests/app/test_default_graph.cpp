// The embedded default motion graph (app/graph/default_graph.hpp): the authored action
// clips import onto the puppet's skeleton, the pruned graph keeps every label,
// its bytes are identical build to build, and paths through it stay continuous.
#include <catch2/catch.hpp>

#include <algorithm>
#include <limits>
#include <memory>

#include "app/graph/default_graph.hpp"
#include "app/config/embedded.hpp"
#include "app/graph/graph_files.hpp"
#include "graph_builder/graph_prune.hpp"
#include "graph_builder/transition_search.hpp"
#include "graph_builder/clip_database.hpp"
#include "runtime/graph/graph_path.hpp"
#include "runtime/gait/puppet.hpp"
#include "runtime/sim/simulation.hpp"
#include "runtime/sim/tick_input.hpp"
#include "tests/graph_path_check.hpp"

using namespace marionette;

namespace {

std::vector<vec3> model_positions(const Clip& clip, int frame) {
    const size_t J = static_cast<size_t>(clip.joint_count());
    std::vector<quat> mr(J);
    std::vector<vec3> mp(J);
    const LocalToModelJob fk{clip.skeleton.parents,
                             {std::span<const quat>(clip.frame_rotations(frame), J),
                              std::span<const vec3>(clip.frame_translations(frame), J)},
                             {mr, mp}};
    REQUIRE(fk.run());
    return mp;
}

// Largest distance any joint moves between consecutive frames.
double max_joint_step(const Clip& clip) {
    double worst = 0.0;
    std::vector<vec3> previous;
    for (int f = 0; f < clip.frame_count; ++f) {
        std::vector<vec3> now = model_positions(clip, f);
        if (f > 0)
            for (size_t j = 0; j < now.size(); ++j)
                worst = std::max(worst, static_cast<double>(glm::length(now[j] - previous[j])));
        previous = std::move(now);
    }
    return worst;
}

const DefaultGraphBuild& default_build() {
    static const DefaultGraphBuild build = build_default_motion_graph_report(SimConfig{}, GraphBuildConfig{});
    return build;
}

}  // namespace

TEST_CASE("default graph: action clips import onto the puppet skeleton and start and end standing", "[default_graph]") {
    const SimConfig config;
    const Skeleton puppet = make_puppet_skeleton(config);
    Simulation sim(config);
    sim.step(TickInput{});
    const PuppetState& standing = sim.state();
    const std::vector<Clip> clips = default_action_clips();
    REQUIRE(clips.size() == default_action_clip_names().size());
    for (size_t i = 0; i < clips.size(); ++i) {
        const Clip& clip = clips[i];
        INFO(clip.name);
        CHECK(clip.name == default_action_clip_names()[i]);
        CHECK(validate_clip(clip).ok());
        CHECK(offline::same_skeleton(puppet, clip.skeleton).ok());
        CHECK(clip.frame_rate == Approx(30.0));
        CHECK(clip.duration() >= 1.0);
        CHECK(clip.duration() <= 3.0);
        // First and last frames stand like the simulated idle pose (joints within
        // 6 cm, positions relative to the pelvis's ground point).
        for (const int frame : {0, clip.frame_count - 1}) {
            const std::vector<vec3> mp = model_positions(clip, frame);
            for (size_t j = 0; j < mp.size(); ++j) {
                const vec3 sim_rel = standing.model_positions[j] - standing.model_positions[0] * vec3(1, 0, 1);
                const vec3 clip_rel = mp[j] - mp[0] * vec3(1, 0, 1);
                INFO("frame " << frame << " joint " << clip.skeleton.joint_names[j]);
                CHECK(glm::length(sim_rel - clip_rel) < 0.06f);
            }
        }
        // Authored with eased curves: no joint moves faster than a waving hand
        // (2.4 m/s, 8 cm per 30 Hz frame), or 4.5 m/s in the jump's arm swing.
        CHECK(max_joint_step(clip) < (clip.name == "jump" ? 0.15 : 0.08));
    }
}

TEST_CASE("default graph: the pruned component keeps every label and clip", "[default_graph]") {
    const DefaultGraphBuild& build = default_build();
    const MotionGraph& g = build.output.graph;
    CHECK(build.clips == 19);  // 15 locomotion captures + 4 authored actions
    CHECK(g.nodes.size() > 100);
    for (const std::string& label : default_graph_labels()) {
        INFO(label);
        const auto it = std::find_if(build.output.prune.labels.begin(), build.output.prune.labels.end(),
                                     [&](const LabelReachability& l) { return l.label == label; });
        REQUIRE(it != build.output.prune.labels.end());
        CHECK(it->clips_kept > 0);
        CHECK(g.label_index(label) >= 0);
    }
    const std::vector<std::string> kept = kept_clip_names(g);
    for (const std::string& action : default_action_clip_names())
        CHECK(std::find(kept.begin(), kept.end(), action) != kept.end());
}

TEST_CASE("default graph: two builds serialize to identical bytes", "[default_graph]") {
    const std::vector<std::uint8_t> a = serialize_motion_graph(default_build().output.graph);
    const std::vector<std::uint8_t> b = serialize_motion_graph(build_default_motion_graph(SimConfig{}, GraphBuildConfig{}));
    CHECK(a.size() > 1000);
    CHECK(a == b);
}

TEST_CASE("default graph: paths from idle reach every label with continuous poses", "[default_graph]") {
    const MotionGraph& g = default_build().output.graph;
    double source_worst = 0.0;
    for (const GraphClip& c : g.clips)
        source_worst = std::max(source_worst, max_joint_step(synthesize_path(g, g.clip_index(c.name), 0, {}, c.frame_count)));
    const int idle = g.clip_index("idle");
    REQUIRE(idle >= 0);
    int start = -1;
    for (size_t n = 0; n < g.nodes.size() && start < 0; ++n)
        if (g.nodes[n].clip == idle) start = static_cast<int>(n);
    REQUIRE(start >= 0);
    GraphPathSearch search(g, 1.0);
    for (size_t l = 0; l < g.labels.size(); ++l) {
        INFO("idle → " << g.labels[l]);
        search.clear_goals();
        search.add_label_goal(static_cast<int>(l));
        REQUIRE(search.run(start));
        const std::vector<std::int32_t> path(search.path().begin(), search.path().end());
        const Clip motion = synthesize_path(g, idle, g.nodes[static_cast<size_t>(start)].frame, path, 5);
        CHECK(max_joint_step(motion) <= 1.5 * source_worst);
    }
}

TEST_CASE("default graph: sliced action queries reach the one-shot answer from every node", "[default_graph][path]") {
    const MotionGraph& g = default_build().output.graph;
    const test::SlicedQueryStats stats = test::check_sliced_queries(g, {1, 5, 64});
    CHECK(stats.found == stats.queries);  // strongly connected, every label kept
    // With the default budget a query is done within the shortest edge it can start
    // on, so a press waits at most the rest of the current edge and one more.
    int shortest_edge_ticks = std::numeric_limits<int>::max();
    const SimConfig config;
    for (const GraphEdge& e : g.edges)
        shortest_edge_ticks = std::min(shortest_edge_ticks, static_cast<int>(e.frames * config.tick_rate_hz / g.frame_rate));
    INFO("most pops " << stats.max_pops << ", shortest edge " << shortest_edge_ticks << " ticks, budget "
                      << config.graph_max_nodes_per_tick);
    CHECK(stats.max_pops <= static_cast<std::int64_t>(shortest_edge_ticks) * config.graph_max_nodes_per_tick);
    CHECK(stats.max_path_edges <= kGraphActionPath);
}

namespace {

struct ActionRun {
    std::vector<std::uint64_t> hashes;
    int press_tick = 0, reached_tick = -1, left_tick = -1, back_to_locomotion_tick = -1;
    int ticks_on_label = 0;
    std::int64_t actions_played = 0;
    double max_joint_move_m = 0.0;
    std::string clip_after;
};

// Drives a simulation from the default graph (`--graph default`'s attach) with
// the stick at `stick_y` (forward), pressing button `button` for 100 ms at 3 s,
// for 12 s; records when the puppet first plays a frame of a clip carrying
// `label`, when it leaves it, when the controller is back in locomotion, and the
// largest world-space joint move in one tick.
ActionRun run_action(const std::shared_ptr<const MotionGraph>& graph, int button, const std::string& label, float stick_y) {
    const SimConfig config;
    Simulation sim(config);
    attach_motion_graph(sim, graph);
    const int label_index = graph->label_index(label);
    REQUIRE(label_index >= 0);
    ActionRun out;
    out.press_tick = 3 * config.tick_rate_hz;
    const int ticks = 12 * config.tick_rate_hz;
    const size_t joints = static_cast<size_t>(graph->joint_count());
    std::vector<vec3> previous;
    for (int tick = 0; tick < ticks; ++tick) {
        TickInput in{};
        in.left_y = static_cast<std::int16_t>(stick_y * kStickScale);
        if (tick >= out.press_tick && tick < out.press_tick + config.tick_rate_hz / 10)
            in.buttons = static_cast<std::uint16_t>(1u << button);
        sim.step(in);
        const PuppetState& s = sim.state();
        out.hashes.push_back(hash_state(s));
        if (!previous.empty())
            for (size_t j = 0; j < joints; ++j)
                out.max_joint_move_m = std::max(out.max_joint_move_m, static_cast<double>(glm::length(s.model_positions[j] - previous[j])));
        previous.assign(s.model_positions.begin(), s.model_positions.begin() + static_cast<std::ptrdiff_t>(joints));
        // The frame being shown: a clip edge's clip, or a transition's source clip
        // (its target clip once the blend is past half way).
        const GraphEdge& e = graph->edges[static_cast<size_t>(s.graph.edge)];
        const bool second_half = e.kind == GraphEdgeKind::transition && s.graph.edge_position >= 0.5f * static_cast<float>(e.frames);
        const int clip = graph->nodes[static_cast<size_t>(second_half ? e.to : e.from)].clip;
        const bool on_label = (graph->clips[static_cast<size_t>(clip)].label_mask >> label_index) & 1u;
        if (tick < out.press_tick) continue;
        if (on_label) {
            ++out.ticks_on_label;
            if (out.reached_tick < 0) out.reached_tick = tick;
        } else if (out.reached_tick >= 0 && out.left_tick < 0) {
            out.left_tick = tick;
            out.clip_after = graph->clips[static_cast<size_t>(clip)].name;
        }
        if (out.reached_tick >= 0 && out.back_to_locomotion_tick < 0 && s.graph.mode == GraphMotionMode::locomotion)
            out.back_to_locomotion_tick = tick;
    }
    out.actions_played = sim.state().graph.actions_played;
    return out;
}

}  // namespace

TEST_CASE("default graph: every face button plays its action while walking and standing, then locomotion resumes",
          "[default_graph][controller]") {
    const auto graph = std::make_shared<const MotionGraph>(default_build().output.graph);
    const SimConfig config;
    const int hz = config.tick_rate_hz;
    const char* const labels[4] = {"jump", "wave", "bow", "look_around"};  // south, east, west, north
    const std::string locomotion[] = {"walk", "run", "turn", "idle", "stop"};
    for (int button = 0; button < 4; ++button)
        for (const float stick_y : {0.5f, 0.0f}) {
            const std::string label = labels[button];
            INFO(kButtonNames[static_cast<size_t>(button)] << " → " << label << (stick_y > 0.0f ? " while walking" : " standing"));
            const ActionRun run = run_action(graph, button, label, stick_y);
            INFO("reached after " << (run.reached_tick - run.press_tick) << " ticks, on it " << run.ticks_on_label
                                  << " ticks, then " << run.clip_after << "; largest joint move " << run.max_joint_move_m << " m");
            REQUIRE(run.reached_tick >= 0);
            // Within two seconds standing; walking, the default graph has to stop first
            // (its action clips start and end standing): within four.
            CHECK(run.reached_tick - run.press_tick <= (stick_y > 0.0f ? 4 : 2) * hz);
            CHECK(run.ticks_on_label >= hz / 2);                 // and played, not just touched
            CHECK(run.left_tick > run.reached_tick);             // then left again
            CHECK(run.back_to_locomotion_tick > run.reached_tick);
            CHECK(run.actions_played == 1);
            // What follows is locomotion: a clip with a locomotion label.
            const int after = graph->clip_index(run.clip_after);
            REQUIRE(after >= 0);
            std::uint32_t mask = 0;
            for (const std::string& l : locomotion) mask |= 1u << graph->label_index(l);
            CHECK((graph->clips[static_cast<size_t>(after)].label_mask & mask) != 0u);
            // No joint jumps: 2.5 cm in a 240 Hz tick is 6 m/s, about the peak speed of
            // a running swing foot (twice the body's). Since the swing path lifts
            // straight up and sets straight down (docs/gait.md, "Swing path"), the
            // captured run's swing foot peaks at 4.9 m/s (2.03 cm a tick) in the
            // locomotion before every action; a pop would be several times that.
            CHECK(run.max_joint_move_m < 0.025);
            // Deterministic: a second run gives the same hash every tick.
            if (button == 0) CHECK(run_action(graph, button, label, stick_y).hashes == run.hashes);
        }
}

TEST_CASE("default graph: the tiled search finds exactly the reference's candidates", "[default_graph][distance]") {
    // The locomotion clips are procedural and periodic, so their distance valleys
    // are flat to ~1e-8 along the diagonal: a search that rounds more than the
    // reference would pick other minima there (the float sgemm path did); below
    // kDistanceNoiseFloor both count as 0.
    const offline::GraphBuildParams params = graph_build_params(GraphBuildConfig{});
    std::vector<Clip> clips = generate_locomotion_clips(SimConfig{}, params.analysis_rate_hz);
    for (Clip& c : default_action_clips()) clips.push_back(std::move(c));
    const offline::LabelRules rules =
        offline::parse_label_rules(std::string(embedded::find("config/graph_labels.toml")), "config/graph_labels.toml");
    const offline::ClipDatabase db = offline::make_clip_database(std::move(clips), {}, rules, params.analysis_rate_hz);
    const double leg = offline::skeleton_leg_length(db.skeleton, db.left_foot >= 0 ? db.left_foot : db.right_foot);
    const std::vector<vec3> p = offline::database_positions(db);
    const offline::FrameFeatures f = offline::compute_frame_features(db, p, params.window_frames, leg);
    offline::CandidateSearchOptions o;
    o.neighbourhood = params.neighbourhood_frames;
    o.threshold = default_build().output.threshold;
    const offline::CandidateSearchResult tiled = offline::find_transition_candidates(f, o);
    const offline::CandidateSearchResult reference = offline::find_transition_candidates_reference(db, p, f, leg, o);
    CHECK(tiled.pair_evaluations == reference.pair_evaluations);
    REQUIRE(tiled.candidates.size() == reference.candidates.size());
    CHECK(tiled.candidates.size() > 100);
    for (size_t c = 0; c < tiled.candidates.size(); ++c) {
        CHECK(tiled.candidates[c].from_frame == reference.candidates[c].from_frame);
        CHECK(tiled.candidates[c].to_frame == reference.candidates[c].to_frame);
    }
}
