#pragma once
// Cheapest paths through a motion graph (Dijkstra, cost = weighted transition
// distance + seconds of motion), and the poses along a path: clip frames placed in
// the world, transitions blended with Kovar's ease weights. The search object owns
// all its memory, sized once from the graph, so a query inside the tick never
// allocates. A query can run in one go (run) or in slices of a bounded number of
// heap pops (begin + advance): the slices reach exactly the one-shot answer, and
// the answer after k pops depends only on (graph, weight, goals, start, k).
#include <cstdint>
#include <span>
#include <vector>

#include "runtime/anim/clip.hpp"
#include "runtime/graph/motion_graph.hpp"

namespace marionette {

// Where a clip frame sits in the pruned graph: the kept node at or before it whose
// clip edge covers it. node < 0 when the frame is not on a kept clip edge.
struct GraphLocation {
    std::int32_t node = -1;         // node with node.frame <= frame
    std::int32_t frames_after = 0;  // frame − node.frame
};
GraphLocation locate_frame(const MotionGraph& graph, int clip, int frame);

// Seconds of motion plus transition_weight × distance, per edge.
double edge_cost(const MotionGraph& graph, const GraphEdge& edge, double transition_weight);

enum class PathSearchStatus : std::int32_t { running = 0, found = 1, unreachable = 2 };

class GraphPathSearch {
public:
    explicit GraphPathSearch(const MotionGraph& graph, double transition_weight = 1.0);

    void set_transition_weight(double weight) { transition_weight_ = weight; }
    double transition_weight() const { return transition_weight_; }

    // Goals are read while the search runs: change them only between queries.
    // clear_goals and add_label_goal are O(1) unless frame goals were added.
    void clear_goals();
    // Every node of a clip carrying the label (bit index into graph.labels).
    void add_label_goal(int label);
    // The node whose clip edge covers (clip, frame), plus the frames still to play.
    bool add_frame_goal(int clip, int frame);

    // Dijkstra from `start`; false when no goal is reachable. Never allocates.
    bool run(int start);

    // The same search in slices: begin() is O(1) (labels are stamped with a
    // query generation, not cleared), advance() pops at most `max_pops` heap
    // entries (each relaxes the popped node's out-edges) and returns where the
    // query stands. Never allocates.
    void begin(int start);
    PathSearchStatus advance(std::int64_t max_pops);
    PathSearchStatus status() const { return status_; }
    std::int32_t start() const { return start_; }
    // Heap pops so far in this query: the measure of its progress.
    std::int64_t pops() const { return pops_; }

    double cost() const { return cost_; }
    int goal_node() const { return goal_node_; }
    // Edges from start to the goal, in order (valid until the next run).
    std::span<const std::int32_t> path() const { return {path_.data(), path_length_}; }
    // Frames to play after arriving at the goal node (frame goals), else 0.
    std::int32_t goal_frames_after() const { return goal_frames_after_; }
    std::int64_t settled_nodes() const { return settled_; }

private:
    double distance(size_t node) const;
    double goal_extra(size_t node) const;
    void finish();

    const MotionGraph& graph_;
    double transition_weight_;
    std::vector<double> distance_;        // valid where stamp_ == generation_
    std::vector<std::int32_t> via_edge_;
    std::vector<std::uint32_t> stamp_;
    std::uint32_t generation_ = 0;
    std::uint32_t goal_labels_ = 0;       // label goals: bit mask over graph.labels
    bool frame_goals_ = false;            // goal_extra_ holds a frame goal
    std::vector<double> goal_extra_;      // < 0: not a frame goal
    std::vector<std::int32_t> goal_after_;
    std::vector<std::pair<double, std::int32_t>> heap_;
    std::vector<std::int32_t> path_;
    size_t path_length_ = 0;
    double cost_ = 0.0;
    double best_ = 0.0;                   // cheapest goal cost found so far in this query
    std::int32_t start_ = -1;
    std::int32_t goal_node_ = -1;
    std::int32_t goal_frames_after_ = 0;
    std::int64_t settled_ = 0;
    std::int64_t pops_ = 0;
    PathSearchStatus status_ = PathSearchStatus::unreachable;
};

// Kovar's ease-in/ease-out weight of the source clip at blend frame p of k:
// α(p) = 2((p+1)/k)³ − 3((p+1)/k)² + 1 (1 → 0; the last blend frame is all target).
float transition_weight(int p, int k);

// One database frame with its roots placed by `world`. Spans hold joint_count.
void graph_frame_pose(const MotionGraph& graph, int global_frame, const PlanarTransform& world,
                      std::span<quat> rotations, std::span<vec3> translations);

// Blend frame p (0 … k−1) of a transition edge, source placed by `world`, target by
// world ∘ align. Returns the contact bits of the dominant side. With `warp`
// (2k floats from transition_time_warp) the two windows are sampled at the
// registered times warp[p] and warp[k + p] (window frames, interpolated)
// instead of both at p; empty: unwarped (Kovar's plain blend).
std::uint8_t graph_transition_pose(const MotionGraph& graph, const GraphEdge& edge, int p, const PlanarTransform& world,
                                   std::span<quat> rotations, std::span<vec3> translations,
                                   std::span<const float> warp = {});

// The registration of one transition's two windows (Kovar and Gleicher,
// "Flexible Automatic Motion Blending with Registration Curves", 2003): the
// source window (the k frames from the edge's source frame) and the target
// window (the k frames before the edge's target frame) are aligned by dynamic
// time warping on a pose distance (Σ over non-root joints of 1 − |q_a·q_b|, in
// double, joint order), steps (1,1), (1,0), (0,1) within a band of
// kWarpBandFraction·k frames of the diagonal, ties to the diagonal, then to
// advancing the source; the path is resampled to k blend frames by arc
// position and smoothed twice with [1 2 1]/4 (end points fixed: both windows
// start and end where the plain blend does, so the edge keeps its k frames and
// its joins). Writes 2k window times to `out` (source times, then target
// times), each non-decreasing from 0 to k − 1; the identity for a clip edge,
// k < 3 or k > kMaxWarpWindowFrames; nothing for `out` not of 2k. Allocates (the k × k table): at graph load and
// offline, never in the tick.
void transition_time_warp(const MotionGraph& graph, const GraphEdge& edge, std::span<float> out);
inline constexpr double kWarpBandFraction = 0.25;
// Windows longer than this (frames) are not warped (the identity): the DTW table
// grows as k², and a file may claim any window (the builder's default is 10).
inline constexpr int kMaxWarpWindowFrames = 64;
// Whether warping every transition of `graph` is affordable: the DTW's cells ×
// joints summed over the transitions under kMaxWarpWork (~0.5 s; the shipped
// graphs need ~10⁶). Past it (a crafted or enormous file) the blends stay plain
// instead of loading for minutes.
bool transition_warps_affordable(const MotionGraph& graph);
inline constexpr double kMaxWarpWork = 5e8;
// The DTW path cost of that alignment and of the diagonal (the plain blend's
// pairing), for tests and `graph info`: the first is never above the second.
void transition_warp_costs(const MotionGraph& graph, const GraphEdge& edge, double& warped, double& diagonal);

PlanarTransform edge_alignment(const GraphEdge& edge);

// The motion along a path (offline: allocates): frames start_frame … of the start
// clip up to the first node, each edge in turn, then `frames_after` frames + 1 of
// the goal node's clip. The result is a clip at the graph's rate, ready for BVH.
Clip synthesize_path(const MotionGraph& graph, int start_clip, int start_frame, std::span<const std::int32_t> edges,
                     int frames_after);

}  // namespace marionette
