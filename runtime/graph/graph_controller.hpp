#pragma once
// Drives a motion graph at the tick rate: plays the graph's frames (stored at its
// analysis rate) with slerp/lerp between neighbouring frames, places the motion
// in the world by accumulating each transition's planar alignment, blends
// transitions with Kovar's ease weights (graph_transition_pose), and at each
// node picks the next edge:
//   - locomotion: a bounded depth-first branch-and-bound over the edges ahead,
//     scoring where the root ends up after `horizon_s` against where the stick's
//     desired velocity would put it; its work per tick is capped and a search is
//     spread over the ticks of the edge being played, so no tick spikes;
//   - actions: a requested label is reached by the cheapest path, its clip is
//     played to its end, then locomotion resumes. The path query (Dijkstra,
//     GraphPathSearch) runs in slices of at most `max_nodes_per_tick` heap pops
//     per tick from the end of the edge being played, while locomotion goes on;
//     if that edge ends first, the query restarts from the end of the next one.
//     Its answer is the one-shot query's, bit for bit.
//     Where the query's scratch lives: its labels and heap are large (nodes +
//     edges), so they stay in the controller, and the state records only what
//     they are a pure function of: the start node (the end of `edge`), the label
//     (`action_label`) and the number of heap pops done (`action_search_pops`).
//     Before slicing on, step() checks that its scratch is that function of this
//     state and otherwise re-derives it (restart, pop `action_search_pops` times,
//     a one-off catch-up): a state copied mid-query (snapshot, retune, a second
//     state stepped by the same controller, another controller) continues
//     exactly as the original would.
//   - facing: steering compares the stick with each frame's facing: the root's
//     +Z axis turned by `facing_offset()`, which estimate_graph_facing() derives
//     once at construction from the direction of travel of the walking clips
//     (0 for the puppet and for CMU data, whose roots face +Z);
//   - attract mode: after `attract_after_s` without input, a random walk whose
//     edge probabilities fall with the transition distance (PRNG in the state).
// The state is plain fixed-size data (no pointers), so it can live in
// PuppetState and be hashed; the controller object holds the const graph and
// scratch sized once at construction, so step() never allocates.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "runtime/anim/pose_spans.hpp"
#include "runtime/graph/graph_path.hpp"
#include "runtime/graph/graph_sample.hpp"
#include "runtime/graph/motion_graph.hpp"

namespace marionette {

inline constexpr int kGraphSearchDepth = 8;     // edges looked ahead at most
inline constexpr int kGraphActionPath = 64;     // edges of a path to an action clip
inline constexpr int kGraphActionButtons = 16;  // TickInput button bits
inline constexpr int kGraphRolloutEdges = 64;   // clip edges a search leaf follows toward the horizon at most

struct GraphControllerConfig {
    double horizon_s = 1.0;             // look-ahead of the locomotion search
    int max_nodes_per_tick = 64;        // search nodes expanded per tick at most
    int branch_depth = 2;               // levels where every out-edge is tried; deeper, the clip continues
    double max_speed = 1.5;             // graph units per second at full stick
    double heading_weight = 1.0;        // heading error (1 − cos) weight vs position error
    double transition_weight = 1.0;     // transition distance weight in every choice
    double attract_after_s = 30.0;      // seconds without input before the random walk
    double attract_temperature = 1.0;   // random walk: weight 1 / (1 + cost / temperature)
    std::uint64_t seed = 1;             // attract-mode PRNG seed
    // Button bit b → graph label index to play on press, −1 for none (resolved
    // from names when the graph is loaded: resolve_graph_actions).
    std::array<std::int32_t, kGraphActionButtons> button_label{};
    GraphControllerConfig() { button_label.fill(-1); }
};

// find_action: locomotion goes on while the path to action_label is searched.
enum class GraphMotionMode : std::int32_t { locomotion = 0, to_action = 1, action = 2, attract = 3, find_action = 4 };

// The facing of a graph's clips relative to the root's +Z axis (radians, a yaw
// about +Y): the mean over walk-labelled clips (all clips when no label is
// `walk`) of the angle from the root's +Z to the direction of travel, at frames
// moving faster than 40 % of their clip's top speed, weighted by speed. Within
// 15° of a multiple of 90° it snaps to it (skeletons face an axis; the residue
// is gait sway and curved paths), and it is 0 when the clips do not move or
// their directions disagree (mean resultant below 0.5). `samples` returns the
// frames used, `agreement` the mean resultant length.
double estimate_graph_facing(const MotionGraph& graph, int* samples = nullptr, double* agreement = nullptr);

// One level of the look-ahead search: the state after the edges chosen so far.
struct GraphSearchLevel {
    std::int32_t node = 0;         // node reached
    std::int32_t next_edge = 0;    // next out-edge (index into its out_edges) to try
    std::int32_t first_edge = -1;  // the edge taken at the root of this branch
    float seconds = 0.0f;          // motion played since the decision node
    float cost = 0.0f;             // transition cost so far
    double angle = 0.0, dx = 0.0, dz = 0.0;  // world placement at `node`
};

struct GraphControllerState {
    std::int32_t edge = -1;          // edge being played
    float edge_position = 0.0f;      // graph frames into the edge, [0, edge.frames)
    double world_angle = 0.0, world_dx = 0.0, world_dz = 0.0;  // placement of the edge's source
    GraphMotionMode mode = GraphMotionMode::locomotion;
    std::uint16_t last_buttons = 0;
    float idle_seconds = 0.0f;       // seconds without stick or button input
    std::uint64_t rng = 1;           // splitmix64 state
    std::int32_t action_label = -1;
    // Path to the action clip, edges in order, and how far along it is.
    std::array<std::int32_t, kGraphActionPath> action_path{};
    std::int32_t action_path_length = 0, action_path_next = 0;
    // find_action: heap pops the path query from the end of `edge` has done.
    std::int64_t action_search_pops = 0;
    // The look-ahead search for the decision at the end of the current edge.
    std::array<GraphSearchLevel, kGraphSearchDepth + 1> search{};
    std::int32_t search_depth = -1;  // −1: no search running
    std::int32_t best_edge = -1;     // best first edge found so far
    float best_score = 0.0f;
    float desired_vx = 0.0f, desired_vz = 0.0f;  // stick velocity the search aims for
    std::uint8_t contacts = 0;       // foot contacts of the pose (kContactLeft | kContactRight)
    std::int64_t decisions = 0, transitions_taken = 0, actions_played = 0, nodes_expanded = 0;
};

struct GraphControllerInput {
    float stick_x = 0.0f, stick_y = 0.0f;  // [-1, 1]; desired direction (x, −y) on XZ, as the gait reads it
    std::uint16_t buttons = 0;
    float dt = 0.0f;
};

class GraphController {
public:
    // Sizes all scratch from the graph; throws std::invalid_argument for an empty or
    // inconsistent graph.
    GraphController(const MotionGraph& graph, const GraphControllerConfig& config);

    const MotionGraph& graph() const { return graph_; }
    const GraphControllerConfig& config() const { return config_; }
    void set_config(const GraphControllerConfig& config);
    // Yaw from the root's +Z to the clips' forward (estimate_graph_facing).
    double facing_offset() const { return facing_offset_; }

    // The state at the first clip edge of the graph, at the origin.
    GraphControllerState initial_state() const;

    // One tick: advances, decides, and writes the pose (joint_count entries, graph
    // units, roots placed in the world: GraphSampleJob). Never allocates. False,
    // with the state and the pose untouched, when the pose spans are not
    // joint_count long or the state is not on an edge of the graph.
    [[nodiscard]] bool step(GraphControllerState& state, const GraphControllerInput& input, LocalPoseOutput pose);

    // The pose of `state` without advancing (false, touching nothing, as for step).
    [[nodiscard]] bool pose(const GraphControllerState& state, LocalPoseOutput pose);

    // Root position (graph units) and facing (radians, facing (sin h, 0, cos h)) at a
    // node under a placement.
    vec3 root_position(int node, const PlanarTransform& world) const;
    double root_heading(int node, const PlanarTransform& world) const;

private:
    GraphSampleJob sample_job(const GraphControllerState& s, LocalPoseOutput pose);
    void start_edge(GraphControllerState& s, int edge) const;
    int choose_next_edge(GraphControllerState& s);
    void search_start(GraphControllerState& s) const;
    void search_run(GraphControllerState& s, int budget) const;
    int random_edge(GraphControllerState& s) const;
    int clip_edge_of(int node) const;
    void advance_action_search(GraphControllerState& s, int budget);
    bool steering(const GraphControllerState& s) const {
        return s.mode == GraphMotionMode::locomotion || s.mode == GraphMotionMode::find_action;
    }

    const MotionGraph& graph_;
    GraphControllerConfig config_;
    std::vector<float> transition_warps_;  // per edge 2·window_frames registered times (graph_sample.hpp)
    GraphPathSearch path_search_;  // the action query's scratch (see the top of this file)
    std::int32_t path_search_label_ = -1;  // label path_search_ is searching for, −1: none yet
    std::vector<quat> sample_rotations_;  // GraphSampleJob's scratch
    std::vector<vec3> sample_translations_;
    std::vector<float> frame_yaw_;  // per database frame: facing in clip coordinates
    double facing_offset_ = 0.0;
    // Per node: seconds (path cost) to the nearest node where the root moves at
    // walking speed, and to the nearest where it stands still. The look-ahead sees
    // only `horizon_s`; these tell it which way the rest of the graph lies (from an
    // idle clip, walking may be several transitions away).
    std::vector<float> seconds_to_moving_, seconds_to_still_;
};

}  // namespace marionette
