#pragma once
// The motion-matching database (Clavet, "Motion Matching and The Road to
// Next-Gen Animation", GDC 2016; Holden et al., "Learned Motion Matching", 2020):
// every frame of the locomotion clips is a place the character may jump to, and
// each is described by a feature vector in its own root frame (the ground point
// under the root joint, turned to the frame's facing):
//   - both feet's positions and velocities,
//   - the hips' (root joint's) velocity,
//   - where the root will be 1/3, 2/3 and 1 s later and which way it will face.
// Each feature group is normalised by its mean and one standard deviation for
// the whole group, then multiplied by its weight ([motion_matching] weights), so
// a squared distance between two vectors weighs the groups as configured.
// Built once, outside the tick (allocates); the search (matching_search.hpp) and
// the controller only read it. Deterministic: double accumulation in frame
// order, owned atan2, no BLAS.
//
// The source frames are a plain view of clip data (MatchingSource): the
// puppet's own clips through the motion graph today, retargeted clips later, as
// long as they share the puppet's joint layout.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "runtime/errors/outcome.hpp"
#include "runtime/math/math.hpp"

namespace marionette {

inline constexpr int kMatchFeatureCount = 27;
inline constexpr int kMatchTrajectoryPoints = 3;           // at 1/3, 2/3 and 1 s
// The search's layout (matching_search.cpp): blocks of kMatchLanes frames summed
// lane-parallel, small boxes of 2 blocks, large boxes of 4 small, top boxes of
// kMatchLanes large ones.
inline constexpr int kMatchLanes = 8;                      // frames per block, large boxes per top box
inline constexpr int kMatchSmallBox = 16;                  // frames per small bounding box (2 blocks)
inline constexpr int kMatchLargeBox = 64;                  // frames per large bounding box (4 small)
inline constexpr int kMatchTopBox = 512;                   // frames per top bounding box (8 large)
inline constexpr int kMatchSmallPerLarge = kMatchLargeBox / kMatchSmallBox;

// Feature groups: [begin, end) in the feature vector.
enum MatchFeatureGroup : int {
    kMatchFootPosition = 0,   // left xyz, right xyz
    kMatchFootVelocity,       // left xyz, right xyz
    kMatchHipsVelocity,       // xyz
    kMatchTrajectoryPosition, // x z at each point
    kMatchTrajectoryFacing,   // facing x z at each point
    kMatchGroupCount
};
inline constexpr std::array<int, kMatchGroupCount + 1> kMatchGroupBegin = {0, 6, 12, 15, 21, 27};

// [motion_matching] feature weights (docs/config.md).
struct MatchingWeights {
    float foot_position = 0.75f;
    float foot_velocity = 1.0f;
    float hips_velocity = 1.0f;
    float trajectory_position = 1.0f;
    float trajectory_facing = 1.5f;
    float of(int group) const;
    bool operator==(const MatchingWeights&) const = default;
};

// One clip of the source: frames [first_frame, first_frame + frame_count).
struct MatchingClipRange {
    std::int32_t first_frame = 0;
    std::int32_t frame_count = 0;
};

// Where the frames come from: local rotations and translations of `joint_count`
// joints per frame, frame after frame, the root (joint 0) in clip coordinates.
struct MatchingSource {
    std::span<const int> parents;                 // topological order, joint 0 the root
    std::span<const quat> rotations;              // [frame * joints + joint]
    std::span<const vec3> translations;           // same layout, source units
    std::span<const std::uint8_t> contacts;       // per frame: bit 0 left foot, bit 1 right foot
    std::span<const MatchingClipRange> clips;     // the clips that enter the database, in order
    // Action clips (a button's labelled clip): in the database after `clips`,
    // played only on request (MatchingInput::action), never a search answer,
    // and not in the statistics the features are normalised by.
    std::span<const MatchingClipRange> actions;
    double frame_rate = 30.0;
    float metres_per_unit = 1.0f;
    double facing_offset = 0.0;                   // yaw from the root's +Z to the clips' forward
    int left_foot = -1, right_foot = -1;          // ankle joints
    int joint_count() const { return static_cast<int>(parents.size()); }
};

struct MatchingDatabase {
    std::int32_t frame_count = 0;
    std::int32_t joint_count = 0;
    double frame_rate = 30.0;
    std::array<std::int32_t, kMatchTrajectoryPoints> trajectory_frames{};  // frames ahead of each point
    std::vector<std::int32_t> source_frame;      // database frame → source frame
    std::vector<std::int32_t> clip_end;          // database frame → one past its clip's last database frame
    std::vector<std::uint8_t> searchable;        // 1: a search may jump here (enough clip left)
    std::int32_t matched_frames = 0;             // frames of the source's clips: [0, matched_frames); actions follow
    std::vector<std::int32_t> action_begin;      // database frame where each action clip starts
    std::vector<float> features;                 // [frame * kMatchFeatureCount + k], normalised and weighted
    std::vector<float> raw_features;             // the same before normalisation (metres, m/s, unit facings)
    std::array<float, kMatchFeatureCount> mean{};
    std::array<float, kMatchFeatureCount> inv_scale{};  // weight / group standard deviation
    // The search's plain data, rebuilt by normalise_matching_database: the
    // searchable frames in k-d order (runs of slots close in feature space), in
    // slots padded to whole top boxes (padding: zero features, no frame):
    //   block_frame [slot]: the database frame in slot block·8 + lane, or −1;
    //   block_features [block][k][lane]: those frames' features, feature-major,
    //     so a block's 8 costs are summed lane-parallel, each lane in feature
    //     order (the same float sums as matching_cost);
    //   block_searchable [block]: bit `lane` set when that slot holds a frame;
    //   bounds of the features over runs of slots, a box with
    //   none empty (lo = +inf, hi = −inf), feature-major like the blocks:
    //   top_lo/hi [group][k][lane] (top box group·8 + lane), large_lo/hi [top][k][lane]
    //   (large box top·8 + lane), small_lo/hi [large][k][s] (small box large·4 + s).
    std::vector<std::int32_t> block_frame;
    std::vector<float> block_features;
    std::vector<std::uint8_t> block_searchable;
    std::vector<float> top_lo, top_hi, large_lo, large_hi, small_lo, small_hi;

    const float* frame_features(int frame) const { return features.data() + static_cast<size_t>(frame) * kMatchFeatureCount; }
    const float* frame_raw(int frame) const { return raw_features.data() + static_cast<size_t>(frame) * kMatchFeatureCount; }
    // raw → normalised, as the frames were.
    void normalise(std::span<const float> raw, std::span<float> out) const;
};

// The features of every frame of `source`'s clips and actions, normalised with
// `weights` by the clips' statistics.
// Fails (naming what is wrong) for an empty or inconsistent source, a foot joint
// missing, a weight that is negative or not finite, or a feature that is not finite.
Outcome build_matching_database(const MatchingSource& source, const MatchingWeights& weights, MatchingDatabase& out);

// Recomputes the normalisation, the normalised features and the boxes from
// raw_features (after build, or after frames were appended): the API a database
// of several sources (the puppet's clips, retargeted clips) is assembled with.
void normalise_matching_database(MatchingDatabase& db, const MatchingWeights& weights);

// World vector → the root frame of a root facing `heading` ((sin h, 0, cos h) is +Z there).
inline vec3 to_root_frame(vec3 v, double sin_h, double cos_h) {
    return vec3(static_cast<float>(cos_h * v.x - sin_h * v.z), v.y, static_cast<float>(sin_h * v.x + cos_h * v.z));
}

}  // namespace marionette
