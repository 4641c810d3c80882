#pragma once
// Filling hidden joints of a capture from a motion database (docs/fill.md):
// joints hidden over a frame range get rotations from the database segment whose
// visible joints best match the clip around the gap (Kovar's point-cloud distance,
// root aligned), time-warped by dynamic time warping and blended into the known
// frames at both borders; `slerp` and `hold` are the baselines. Offline code:
// allocates freely, throws ImportError on bad input.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "runtime/anim/clip.hpp"

namespace marionette::offline {

enum class FillMethod { graph, slerp, hold };

// "graph", "slerp", "hold"; throws ImportError naming `option` otherwise.
FillMethod parse_fill_method(const std::string& text, const std::string& option);
const char* fill_method_name(FillMethod method);

// The top joint of a group for skeletons whose names follow the CMU ASF or the
// common BVH conventions (lfemur / LeftUpLeg, lhumerus / LeftArm, lowerneck / Neck),
// or -1. Groups: left_leg, right_leg, left_arm, right_arm, head.
int find_group_root(const Skeleton& skeleton, const std::string& group);

// `--hide` text: comma-separated joint names or groups (left_leg, right_leg,
// left_arm, right_arm, head, legs, arms). A joint hides its whole subtree. Returns
// one flag per joint. Throws ImportError naming `option` for an unknown joint or
// group (listing what exists), an empty list, or the root.
std::vector<bool> resolve_hidden_joints(const Skeleton& skeleton, const std::string& spec, const std::string& option);

struct FillGap {
    std::vector<bool> hidden;  // per joint, closed under subtrees
    int first = 0, last = 0;   // inclusive frame range of the clip, at its own rate
};

// `A:B`, 0-based inclusive; throws ImportError naming `option` when malformed or
// outside [0, frame_count).
FillGap parse_fill_frames(const std::string& text, int frame_count, const std::string& option);

// The database as the search reads it: every clip at `rate`, and the model-space
// position of every joint of every frame.
struct FillDatabase {
    Skeleton skeleton;
    double rate = 30.0;
    std::vector<Clip> clips;
    std::vector<std::vector<vec3>> positions;  // per clip, frame-major
    std::int64_t frame_count() const;
};

// Resamples and runs FK once. Every clip must share the first clip's skeleton
// (the check is the caller's: `check_fill_skeleton`).
FillDatabase prepare_fill_database(std::vector<Clip> clips, double rate = 30.0);

// Ok when `db` has the same joint names and hierarchy as `input`; otherwise says
// what differs and that retargeting does not exist yet.
Outcome check_fill_skeleton(const Skeleton& input, const Skeleton& db);

struct FillOptions {
    FillMethod method = FillMethod::graph;
    double window_s = 0.5;         // matched context on each side of the gap
    // Gaps up to `interp_blend_s` blend from slerp (at 0 s) to the graph's motion
    // (at `interp_blend_s`), so short gaps stay as good as interpolation.
    double interp_blend_s = 0.5;
    int refine_candidates = 8;     // coarse matches refined with DTW
    double ease_s = 0.1;           // velocity ease at each border (0: none)
    int blend_matches = 5;         // the best refined matches averaged (weights ∝ 1 / distance)
    // Weight (against 1 per joint) of the root's position 0.1 s ahead in each
    // frame's point cloud: compares the root's velocity in the body's frame, which
    // the per-frame alignment otherwise discards (docs/fill.md).
    double velocity_weight = 10.0;
    // Half-width (s) of the smoothing of the hidden chains' visible parents: the
    // graph fill of a chain's top joint follows the parent's smoothed rotation, so
    // the capture's frame-to-frame jitter of a pelvis or clavicle does not reach the
    // filled limb (docs/fill.md). 0: fill in the parent's own frame.
    double parent_smooth_s = 0.05;
    // Gaps longer than this are filled whole first, then again in equal pieces
    // no longer than it, one after the other, each between the frame before it
    // (known, or the previous piece's fill) and the whole fill after it, so
    // database motion shorter than the gap can match (docs/fill.md). 0: whole only.
    double piece_s = 2.0;
    // Database frames between the coarse search's starts (DTW then refines the
    // best); the pieces' searches use 2 (docs/fill.md, speed).
    int coarse_stride = 1;
    // Evaluation only (`fill-eval --oracle-match`): the search also sees the hidden
    // joints' values inside the gap — which the clip must still hold (the truth) —
    // so the match is the best in hindsight. Separates a wrong match from what
    // even the best database motion gets wrong.
    bool oracle_match = false;
};

// Which database motion filled a gap (graph method).
struct FillMatch {
    bool found = false;            // false: no database segment fits; slerp was used
    int clip = -1;
    double start_s = 0.0;          // of the matched segment in the database clip
    double scale = 1.0;            // database seconds per input second (before DTW)
    double distance = 0.0;         // mean squared distance per point, file units²
    double graph_weight = 1.0;     // 1 − the short-gap blend toward slerp
};

// Fills one gap of `clip` in place: only the hidden joints' rotations (and
// animated translations) on frames first..last change. `db` may be null for slerp
// and hold. Returns the match (graph method).
FillMatch fill_gap(Clip& clip, const FillGap& gap, const FillDatabase* db, const FillOptions& options);

// Model-space positions of every joint and then every end site, per frame
// (frame-major, joint_count + end sites per frame).
std::vector<vec3> model_positions_with_end_sites(const Clip& clip);
// Frames first..last only (row 0 is frame `first`).
std::vector<vec3> model_positions_with_end_sites(const Clip& clip, int first, int last);

// xxHash64 of bytes: the content hash that refuses the input clip in its own database.
std::uint64_t fill_content_hash(std::span<const std::uint8_t> bytes);

}  // namespace marionette::offline
