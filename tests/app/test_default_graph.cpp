// The embedded default motion graph (app/default_graph.hpp): the authored action
// clips import onto the puppet's skeleton, the pruned graph keeps every label,
// its bytes are identical build to build, and paths through it stay continuous.
#include <catch2/catch.hpp>

#include <algorithm>

#include "app/default_graph.hpp"
#include "app/embedded.hpp"
#include "app/graph_files.hpp"
#include "motion_graph/transition_search.hpp"
#include "motion_graph/clip_database.hpp"
#include "runtime/graph_path.hpp"
#include "runtime/puppet.hpp"
#include "runtime/simulation.hpp"

using namespace marionette;

namespace {

std::vector<vec3> model_positions(const Clip& clip, int frame) {
    const size_t J = static_cast<size_t>(clip.joint_count());
    std::vector<quat> mr(J);
    std::vector<vec3> mp(J);
    LocalToModelJob fk{clip.skeleton.parents, std::span<const quat>(clip.frame_rotations(frame), J),
                       std::span<const vec3>(clip.frame_translations(frame), J), mr, mp};
    fk.run();
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
    static const DefaultGraphBuild build = build_default_motion_graph_report(SimConfig{});
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
        CHECK(validate_clip(clip).empty());
        CHECK(graph::skeleton_mismatch(puppet, clip.skeleton).empty());
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
    CHECK(build.clips == 15);
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
    const std::vector<std::uint8_t> b = serialize_motion_graph(build_default_motion_graph(SimConfig{}));
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

TEST_CASE("default graph: the tiled search finds exactly the reference's candidates", "[default_graph][distance]") {
    // The locomotion clips are procedural and periodic, so their distance valleys
    // are flat to ~1e-8 along the diagonal: a search that rounds more than the
    // reference would pick other minima there (the float sgemm path did); below
    // kDistanceNoiseFloor both count as 0.
    const graph::GraphBuildParams params = graph_build_params(SimConfig{});
    std::vector<Clip> clips = generate_locomotion_clips(SimConfig{}, params.analysis_rate_hz);
    for (Clip& c : default_action_clips()) clips.push_back(std::move(c));
    const graph::LabelRules rules =
        graph::parse_label_rules(std::string(embedded::find("config/graph_labels.toml")), "config/graph_labels.toml");
    const graph::ClipDatabase db = graph::make_clip_database(std::move(clips), {}, rules, params.analysis_rate_hz);
    const double leg = graph::skeleton_leg_length(db.skeleton, db.left_foot >= 0 ? db.left_foot : db.right_foot);
    const std::vector<vec3> p = graph::database_positions(db);
    const graph::FrameFeatures f = graph::compute_frame_features(db, p, params.window_frames, leg);
    graph::CandidateSearchOptions o;
    o.neighbourhood = params.neighbourhood_frames;
    o.threshold = default_build().output.threshold;
    const graph::CandidateSearchResult tiled = graph::find_transition_candidates(f, o);
    const graph::CandidateSearchResult reference = graph::find_transition_candidates_reference(db, p, f, leg, o);
    CHECK(tiled.pair_evaluations == reference.pair_evaluations);
    REQUIRE(tiled.candidates.size() == reference.candidates.size());
    CHECK(tiled.candidates.size() > 100);
    for (size_t c = 0; c < tiled.candidates.size(); ++c) {
        CHECK(tiled.candidates[c].from_frame == reference.candidates[c].from_frame);
        CHECK(tiled.candidates[c].to_frame == reference.candidates[c].to_frame);
    }
}
