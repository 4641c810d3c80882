#pragma once
// Key-pose graphs (issue #15, "key-pose graphs"; docs/motion-graph.md): instead of
// every frame, the graph's nodes are key poses taken from the clips at local
// minima of whole-body joint speed, thinned so no two are closer than a
// pose-difference threshold; edges link key poses whose difference is under a
// (larger) link threshold, cost = that difference. A path between two key poses
// (Dijkstra) becomes an animation by interpolating from pose to pose. The pose
// difference is the motion graph's point-cloud distance over one frame
// (transition_search.hpp: the root aligned on the ground plane, mean squared
// joint distance in leg lengths²). Offline code: allocates freely.
#include <cstdint>
#include <string>
#include <vector>

#include "graph_builder/clip_database.hpp"
#include "runtime/anim/clip.hpp"
#include "runtime/math/planar_alignment.hpp"

namespace marionette::offline {

struct KeyPose {
    std::string clip;   // source clip name
    std::int32_t frame = 0;  // frame of that clip at the graph's rate
    double speed = 0.0; // whole-body joint speed there (leg lengths per second, RMS over joints)
    std::vector<quat> rotations;     // local, one per joint
    std::vector<vec3> translations;  // local, one per joint
};

struct KeyPoseEdge {
    std::int32_t from = 0;  // from < to: the graph is undirected
    std::int32_t to = 0;
    double cost = 0.0;      // pose difference
};

struct KeyPoseGraph {
    Skeleton skeleton;
    std::vector<bool> animated_translation;
    std::vector<float> joint_weights;
    double frame_rate = 30.0;
    double length_unit = 1.0;
    double leg_length = 1.0;        // the distances' scale, skeleton units
    double thin_threshold = 0.0;    // no two key poses closer than this
    double link_threshold = 0.0;    // edges below this
    double step = 1.0;              // interpolation: largest joint move per frame, skeleton units
    std::vector<KeyPose> poses;     // id = index
    std::vector<KeyPoseEdge> edges; // sorted by (from, to)
};

struct KeyPoseParams {
    // Absolute thresholds (leg lengths²) when > 0, else these percentiles of the
    // differences between all pairs of speed minima (before thinning).
    double thin_threshold = 0.0;
    double link_threshold = 0.0;
    double thin_percentile = 2.0;
    double link_percentile = 20.0;
    int minimum_neighbourhood = 3;  // a minimum is below its ±h frames
};

struct KeyPoseBuildReport {
    std::int64_t frames = 0;
    std::int64_t minima = 0;        // speed minima before thinning
    std::int64_t components = 0;    // connected components of the result
    std::int64_t largest_component = 0;
};

// Ok when the graph is consistent (sizes, skeleton order, edge ends and costs),
// else what is wrong, naming the pose or edge.
Outcome validate_key_pose_graph(const KeyPoseGraph& g);

KeyPoseGraph build_key_pose_graph(const ClipDatabase& db, const KeyPoseParams& params, KeyPoseBuildReport* report = nullptr);

// Pose difference of two key poses, and the alignment placing b onto a.
double key_pose_difference(const KeyPoseGraph& g, int a, int b, PlanarTransform* align = nullptr);

// Recomputes the edges from the poses and g.link_threshold (all pairs below it).
void link_key_poses(KeyPoseGraph& g);

// Connected components: component id per pose (numbered by their smallest pose).
std::vector<std::int32_t> key_pose_components(const KeyPoseGraph& g);

// Dijkstra from `from` to `to`: the pose ids along the cheapest path (both ends
// included), empty when `to` cannot be reached. Ties go to the smaller pose id,
// so the answer is the same on every machine.
std::vector<std::int32_t> key_pose_path(const KeyPoseGraph& g, int from, int to, double* cost = nullptr);

// The animation along a path: each key pose placed onto the previous one by the
// planar alignment (root aligned), then from pose to pose rotations slerped and
// translations lerped with smoothstep timing (zero speed at the key poses, as
// at the speed minima they were taken from) over enough frames that no joint
// moves more than g.step per frame at the mean rate. A clip at g.frame_rate.
Clip synthesize_key_pose_path(const KeyPoseGraph& g, const std::vector<std::int32_t>& path);

// Largest per-frame joint move over a clip and its 95th percentile (model
// space, skeleton units): the "pops" check of the tests and the CLI.
struct PopStats {
    double largest = 0.0;
    double p95 = 0.0;
};
PopStats clip_pop_stats(const Clip& clip);

}  // namespace marionette::offline
