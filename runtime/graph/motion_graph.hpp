#pragma once
// The motion graph as plain data (Kovar, Gleicher & Pighin, "Motion Graphs",
// SIGGRAPH 2002): the database frames of every clip at the analysis rate, and a
// directed graph whose nodes are points inside clips and whose edges are either a
// run of consecutive frames of one clip or a blended transition to another clip.
// This header is the run-time side: data and the .mgraph byte format (no file
// I/O here: bytes in, bytes out). The offline builder, pruning included, is
// graph_builder/.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "runtime/math/planar_alignment.hpp"
#include "runtime/anim/skeleton.hpp"

namespace marionette {

inline constexpr std::uint32_t kMotionGraphVersion = 1;
inline constexpr int kMaxGraphLabels = 32;  // labels are a 32-bit mask per clip

// Foot contact bits per database frame.
inline constexpr std::uint8_t kContactLeft = 1;
inline constexpr std::uint8_t kContactRight = 2;

struct GraphClip {
    std::string name;              // file name without extension
    std::uint32_t label_mask = 0;  // bit b: labels[b]
    std::int32_t first_frame = 0;  // index of frame 0 in MotionGraph::rotations etc.
    std::int32_t frame_count = 0;
};

struct GraphNode {
    std::int32_t clip = 0;
    std::int32_t frame = 0;  // 0-based frame of the clip at the analysis rate
};

enum class GraphEdgeKind : std::uint8_t { clip = 0, transition = 1 };

// A clip edge plays frames from.frame … to.frame−1 of one clip. A transition edge
// from (A, i) to (B, j+1) plays k frames A_{i+p} blended into B_{j−k+1+p}
// (p = 0 … k−1) with B placed by `align` (B's coordinates → A's), then continues at
// B_{j+1}. Either way, arriving at `to` means its frame plays next.
struct GraphEdge {
    std::int32_t from = 0;
    std::int32_t to = 0;
    GraphEdgeKind kind = GraphEdgeKind::clip;
    std::int32_t frames = 0;  // frames played along the edge
    float cost = 0.0f;        // transition distance (0 for clip edges)
    float align_angle = 0.0f;
    float align_dx = 0.0f;
    float align_dz = 0.0f;
};

// What the build found, kept in the file so `graph info` can show it.
struct GraphBuildStats {
    std::int64_t frames = 0;          // database frames at the analysis rate
    std::int64_t pair_evaluations = 0;
    std::int64_t candidates = 0;      // local minima below the threshold
    std::int64_t nodes_before = 0;
    std::int64_t edges_before = 0;
    std::int64_t frames_kept = 0;     // frames on kept clip edges
    double threshold = 0.0;           // the absolute distance threshold used
    double build_seconds = 0.0;
};

struct MotionGraph {
    std::uint64_t source_hash = 0;    // hash of the source files' bytes and the build parameters
    // What the graph was built from, so a stale graph can be rebuilt.
    std::string source_asf;
    std::vector<std::string> source_clips;
    std::string source_labels;

    Skeleton skeleton;
    std::vector<bool> animated_translation;
    double length_unit = 1.0;
    double frame_rate = 30.0;         // analysis rate of the stored frames
    std::int32_t window_frames = 10;  // k: transition length and distance window
    float leg_length = 1.0f;          // file units; distances are divided by its square
    std::int32_t left_foot = -1;      // joint indices used for contacts, or −1
    std::int32_t right_foot = -1;

    std::vector<std::string> labels;
    std::vector<GraphClip> clips;
    std::vector<quat> rotations;      // [frame * joints + joint], frames of all clips
    std::vector<vec3> translations;
    std::vector<std::uint8_t> contacts;  // per frame, kContactLeft | kContactRight

    std::vector<GraphNode> nodes;
    std::vector<GraphEdge> edges;     // sorted by `from` (then `to`)
    std::vector<std::int32_t> edge_begin;  // node n's edges: [edge_begin[n], edge_begin[n+1])

    GraphBuildStats stats;

    int joint_count() const { return skeleton.joint_count(); }
    int label_index(const std::string& label) const;
    int clip_index(const std::string& name) const;
    std::span<const GraphEdge> out_edges(int node) const {
        return {edges.data() + edge_begin[static_cast<size_t>(node)],
                static_cast<size_t>(edge_begin[static_cast<size_t>(node) + 1] - edge_begin[static_cast<size_t>(node)])};
    }
    int edge_index(const GraphEdge& e) const { return static_cast<int>(&e - edges.data()); }
};

// Sorts edges by source and fills edge_begin. Call after changing nodes/edges.
void index_edges(MotionGraph& graph);

// Ok when sizes and indices are consistent, otherwise what is wrong.
Outcome validate_motion_graph(const MotionGraph& graph);

// The .mgraph format (docs/motion-graph.md): little-endian, versioned, with an
// xxHash64 of the payload. deserialize throws ImportError naming `file_name` and
// the byte offset of the problem.
std::vector<std::uint8_t> serialize_motion_graph(const MotionGraph& graph);
MotionGraph deserialize_motion_graph(std::span<const std::uint8_t> bytes, const std::string& file_name);
// The source hash alone (header only), for stale checks; throws like deserialize.
std::uint64_t motion_graph_source_hash(std::span<const std::uint8_t> bytes, const std::string& file_name);

}  // namespace marionette
