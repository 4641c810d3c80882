#pragma once
// Motion matching at the tick rate ([motion] source = "matching",
// docs/motion-matching.md):
//   - the stick's velocity and direction drive critically damped springs
//     (trajectory_spring.hpp): the desired trajectory;
//   - the database frame being played advances with time; its root motion moves
//     the character, and the character's root is pulled toward the spring's
//     position and facing (halflife `correction_halflife_s`), so the distance
//     covered is the stick's, not the clip's (the feet are pinned afterwards by
//     the foot placement job, so this does not slide them);
//   - every `search_interval_s`, when the desired trajectory departs from the
//     frame's own by more than `search_threshold_m`, or at the end of a clip,
//     the database is searched (search_matching_accelerated) for the frame whose
//     features best match the current frame's with the desired trajectory, and
//     the character jumps there;
//   - every jump is inertialized (Bollo; Holden): the offsets between the pose
//     shown and the new frame (per joint a rotation vector and a translation) and
//     the offsets' velocities (the shown pose's velocity − the new frame's) decay
//     to zero as critically damped springs of halflife `inertialization_s` / 3,
//     so neither the pose nor its velocity jumps;
//   - an action (MatchingInput::action: a button's labelled clip, which the
//     motion graph supplies) is entered by such a jump to its first frame and
//     played to its end with its own root motion (no search, no correction
//     toward the stick's spring, which waits at the root); at its end a search
//     jumps back into the locomotion, inertialized the same way.
// The state is plain fixed-size data (it lives in PuppetState and is hashed);
// the controller holds the database and its scratch, sized at construction, so
// step() never allocates.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "runtime/anim/pose_spans.hpp"
#include "runtime/matching/matching_database.hpp"
#include "runtime/matching/matching_search.hpp"
#include "runtime/matching/trajectory_spring.hpp"

namespace marionette {

inline constexpr int kMatchMaxJoints = 64;

// [motion_matching] run-time keys (docs/config.md).
struct MatchingControllerConfig {
    float search_interval_s = 0.1f;        // a search at least this often
    float search_threshold_m = 0.15f;      // … and whenever the desired trajectory is this far from the frame's
    float inertialization_s = 0.25f;       // a jump's offsets decay with halflife inertialization_s / 3
    float velocity_halflife_s = 0.12f;     // desired velocity spring
    float facing_halflife_s = 0.15f;       // desired facing spring
    float correction_halflife_s = 0.08f;   // the root is pulled toward the spring with this halflife
};

struct MatchingState {
    std::int32_t frame = 0;          // database frame being played
    float frame_time = 0.0f;         // [0, 1): fraction of the way to the next frame
    double world_angle = 0.0, world_dx = 0.0, world_dz = 0.0;  // clip (metres) → world placement
    TrajectorySpring spring{};       // the desired trajectory's present
    float since_search = 0.0f;       // seconds since the last search
    float since_jump = 1e6f;         // seconds since the last jump (offsets are zero from 4 × inertialization_s)
    float last_cost = 0.0f;          // cost of the last search's answer
    std::uint8_t contacts = 0;       // foot contacts of the frame played
    std::int32_t action = -1;        // the action clip playing (database action index), −1: locomotion
    std::uint16_t held_buttons = 0;  // the pad's buttons last tick (the caller's, for presses)
    std::int64_t searches = 0, jumps = 0;
    // Pose shown = exp(offset_rotation) · frame's rotation (a rotation vector, radians,
    // in the joint's parent frame; the root's in the world), frame's translation +
    // offset_translation; each with its velocity (rad/s, m/s), decaying as springs.
    std::array<vec3, kMatchMaxJoints> offset_rotation{};
    std::array<vec3, kMatchMaxJoints> offset_angular_velocity{};
    std::array<vec3, kMatchMaxJoints> offset_translation{};
    std::array<vec3, kMatchMaxJoints> offset_velocity{};
};

struct MatchingInput {
    TrajectoryGoal goal{};          // desired velocity (world m/s) and facing
    float dt = 0.0f;
    // Start this action clip (an index into the database's action_begin) this
    // tick; −1, an index out of range or an action already playing: none.
    std::int32_t action = -1;
};

class MatchingController {
public:
    // Keeps `source` (the frames' storage) and `db` by reference: both must
    // outlive the controller. Throws std::invalid_argument when they disagree
    // (joint counts, frames) or the skeleton has more than kMatchMaxJoints joints.
    MatchingController(const MatchingSource& source, const MatchingDatabase& db, const MatchingControllerConfig& config);

    const MatchingDatabase& database() const { return db_; }
    void set_config(const MatchingControllerConfig& config) { config_ = config; }

    // A state playing the database's first searchable frame, its root placed at
    // `position` (x, z) facing `heading`, the springs there at rest.
    MatchingState initial_state(vec3 position, float heading) const;
    // Re-places `state`'s motion so its root is at `position` facing `heading`
    // (a change of source into matching), springs at rest there, offsets cleared.
    void place(MatchingState& state, vec3 position, float heading) const;

    // One tick: springs, advance, root correction, search and jump, pose (local,
    // metres, root in the world). Never allocates. False, touching nothing, for
    // spans not of the joint count or a state off the database.
    [[nodiscard]] bool step(MatchingState& state, const MatchingInput& input, LocalPoseOutput pose);
    // The pose of `state` without advancing (false, touching nothing, as step).
    [[nodiscard]] bool pose(const MatchingState& state, LocalPoseOutput pose) const;

    // Root position (metres, world, y the clip's root height) and facing of the state's frame.
    vec3 root_position(const MatchingState& state) const;
    float root_heading(const MatchingState& state) const;
    // Largest distance (m, ground plane) between the desired trajectory's points
    // and the current frame's (the search trigger).
    float trajectory_departure(const MatchingState& state, const TrajectoryGoal& goal) const;

private:
    bool valid(const MatchingState& s, LocalPoseOutput pose) const;
    void sample(const MatchingState& s, LocalPoseOutput out, bool offsets) const;
    // Per joint: the frame's angular velocity (rad/s, as the offsets: parent frame,
    // root in the world) and translation velocity (m/s), from the frame to the next.
    void frame_velocities(const MatchingState& s, std::span<vec3> angular, std::span<vec3> linear) const;
    void decay_offsets(MatchingState& s, float dt) const;
    bool offsets_live(const MatchingState& s) const { return s.since_jump < 4.0f * config_.inertialization_s; }
    void correct_root(MatchingState& s, float dt) const;
    void desired_features(const MatchingState& s, const TrajectoryGoal& goal, std::span<float> raw) const;
    void jump(MatchingState& s, int frame);

    MatchingSource source_;
    const MatchingDatabase& db_;
    MatchingControllerConfig config_;
    std::vector<quat> shown_rotations_;     // the pose shown before a jump
    std::vector<vec3> shown_translations_;
    std::vector<vec3> old_angular_, old_linear_;  // the old frame's velocities at a jump
};

}  // namespace marionette
