#pragma once
// Procedural foot placement on top of a clip pose (the motion graph's
// `graph_feet` source): the clip was recorded on flat ground and its blends
// slide the feet a little, so
//   - the body is raised to the ground under the feet (the lower of the two, so
//     the other leg bends to reach its higher ground), following at a rate;
//   - each foot the clip marks in contact, and that the clip moves slower than
//     kPinMaxSpeed, is pinned where it touched down and held there by the two-bone
//     IK until the clip lifts it; then it eases back to the clip's own path;
//   - a foot is placed on its own ground height, which eases (at most
//     kFootGroundSpeed; smooth_feet: a spring) toward the highest ground under it and up to
//     kFootLookAheadM ahead of it, so a foot rises onto a step before its toes
//     reach the riser, not at it;
//   - a planted foot tilts to the ground's normal.
// A job (runtime/anim/pose_spans.hpp): plain state in and out, spans in and
// out, no allocation; run() returns false, touching neither, on bad input. The
// legs are found by joint index (hip = knee's parent, knee = ankle's parent),
// so it works for any skeleton whose foot joints the graph names; segment
// lengths are read from the pose's own local translations, so scaled graphs work.
#include <array>
#include <cstdint>
#include <span>

#include "runtime/anim/pose_spans.hpp"
#include "runtime/ground/terrain.hpp"
#include "runtime/math/math.hpp"

namespace marionette {

struct FootPin {
    vec3 pin{0.0f};              // where the ankle is held while the clip's foot is in contact (world, m)
    vec3 placed{0.0f};           // where the ankle was put last tick: a new pin starts there, so nothing jumps
    vec3 clip_previous{0.0f};    // the clip's ankle last tick (world, before placement): its speed
    float ground = 0.0f;         // ground height the foot is placed on, eased toward the ground ahead of it
    float release = 1.0f;        // 0 held at the pin … 1 following the clip's foot
    float plant = 0.0f;          // 0 the clip's foot rotation … 1 tilted to the ground: eased both ways
    std::int32_t contact = 0;    // 0 free, 1 pinned, 2 in contact but let go (the pin slipped too far from the clip)
    // smooth_feet only (matching), else untouched:
    vec3 release_offset{0.0f};   // placed − clip's ankle when the pin let go, decaying (critically damped) to 0
    vec3 release_velocity{0.0f}; // its rate (m/s): starts at −(clip ankle's velocity), so the foot leaves at rest
    vec3 unlifted_previous{0.0f};// the ankle last tick before the lift: the foot's velocity for the look-ahead
    float lift = 0.0f;           // metres the foot is raised above its placement, ≥ the depth it would penetrate
    float lift_velocity = 0.0f;  // its rate (m/s)
    float ground_velocity = 0.0f;// the rate (m/s) of `ground` while free: its critically damped spring
    vec3 hold_offset{0.0f};      // horizontal: a free foot held back from a riser its lift has not cleared, decaying to 0
    vec3 hold_velocity{0.0f};    // its rate (m/s)
    vec3 tilt_normal{0.0f, 1.0f, 0.0f};  // the ground normal the foot tilts to, following the one under it (critically damped)
    vec3 tilt_normal_velocity{0.0f};     // its rate (1/s)
};

struct FootPlacementState {
    std::array<FootPin, 2> feet{};
    float body_offset = 0.0f;    // metres the body is raised to meet the ground
    // smooth_feet only: metres the body is lowered so every pinned ankle stays
    // within its leg's reach (lower_for_reach), and its rate (m/s).
    float reach_drop = 0.0f;
    float reach_drop_velocity = 0.0f;
    std::int32_t started = 0;    // 0 until a tick has placed the feet
};

struct FootPlacementLeg {
    std::int32_t hip = -1, knee = -1, ankle = -1;
    // The foot's lower points beyond the ankle, for keep_above_ground
    // (add_foot_tips): the toe joint (the ankle's first child) and the end site
    // past the toe (an offset in metres in tip_parent's frame); −1: none.
    std::int32_t toe = -1, tip_parent = -1;
    vec3 tip{0.0f};
};

struct FootPlacementRig {
    std::array<FootPlacementLeg, 2> legs{};  // left, right
    std::int32_t root = 0;
    bool valid = false;          // both legs have hip, knee and ankle joints
};

// The legs of a skeleton from its foot (ankle) joints; invalid when a foot is
// missing or has fewer than two ancestors below the root.
FootPlacementRig make_foot_placement_rig(std::span<const int> parents, int left_ankle, int right_ankle);

// Fills each leg's toe joint (the ankle's first child) and the end site past
// the toe (or past the ankle without a toe), its offset scaled to metres. The
// skeleton's end sites: parents and offsets, parallel.
void add_foot_tips(FootPlacementRig& rig, std::span<const int> parents, std::span<const int> end_site_parents,
                   std::span<const vec3> end_site_offsets, float metres_per_unit);

// A pin that drifts this far (horizontally) from the clip's foot is let go, so a
// long blend cannot stretch the leg out of reach.
inline constexpr float kMaxPinSlipM = 0.25f;
// The clip's contact flags come from thresholds loose enough for any capture; a
// foot the clip still moves faster than this (m/s, on the ground plane) is not pinned.
inline constexpr float kPinMaxSpeed = 0.35f;
// How fast (m/s) a foot's ground height may change, and how far ahead (m) of the
// ankle, along its motion, the highest ground is looked for: past the toes of an
// adult foot, so the toes clear a riser the ankle has not reached.
inline constexpr float kFootGroundSpeed = 3.0f;
inline constexpr float kFootLookAheadM = 0.35f;
// smooth_feet's lift: how far ahead (s) the foot's penetration is predicted,
// and the lift spring's halflife (s).
inline constexpr float kLiftLookAheadS = 0.1f;
inline constexpr float kLiftHalflifeS = 0.04f;
// smooth_feet's ground: the halflife (s) of the spring that carries a free
// foot's ground height toward the highest ground under and ahead of it (graph_feet
// keeps the kFootGroundSpeed rate limit).
inline constexpr float kFootGroundHalflifeS = 0.05f;
// smooth_feet's hold: a free foot whose lift has not cleared a riser is held back
// this far (m) short of it, and the hold-back then decays with this halflife (s).
inline constexpr float kHoldMarginM = 0.01f;
inline constexpr float kHoldHalflifeS = 0.05f;
// smooth_feet's tilt: halflife (s) of the spring that carries the normal a foot
// tilts to toward the ground's normal under it. The terrain's normal is
// discontinuous where a slope meets the flat (a crease): read at one point, a
// foot crossing it while planted or easing out of the plant turned by the
// slope's whole angle in one tick (3,665 °/s on the default slope run).
inline constexpr float kTiltHalflifeS = 0.05f;

// One tick of smooth_feet's tilt spring: `normal` (rate `velocity`, 1/s) is
// carried toward `ground_normal` as a critically damped spring per component
// (halflife kTiltHalflifeS; e^−x as the rational 1/(1 + x + 0.48x² + 0.235x³),
// no libm); dt ≤ 0 leaves it. Returns `normal` renormalised (`ground_normal` if
// it is degenerate). Its envelope: with every ground normal within an angle α
// of some axis (α < 90°), the returned normal turns at most
// (2y/e)·tan α rad/s, y = 2 ln 2 / kTiltHalflifeS (a single step of θ from
// rest: α = θ/2, ~154 °/s for 15°); held, it converges to the held normal.
vec3 step_tilt_normal(vec3& normal, vec3& velocity, vec3 ground_normal, float dt);

// smooth_feet's soft reach: a free leg whose target lies near or past full
// reach is the IK's ill-conditioned case (the knee angle's rate grows without
// bound as the leg straightens: on the retargeted CMU stairs the knee went 17°
// → 30° in three ticks at 0.99 → 0.97 of the leg, 1,681 °/s). So a target
// farther from the hip (root) than reach − width is pulled in to the distance
// start + width·(1 − e^−(d − start)/width), start = reach − width (e^−x as
// the rational of the springs, no libm): continuous with its first derivative
// at start, increasing, and short of reach (far out, rounding reaches it). width ≤ 0 or a nearer
// target: the target unchanged. The job's width is kSoftReachFraction of the
// leg, eased out as the foot plants.
vec3 soften_reach(vec3 root, vec3 target, float reach, float width);
inline constexpr float kSoftReachFraction = 0.03f;

// smooth_feet's pinned reach: the soft reach (soften_reach with `width`, then the
// two-bone IK's own, from `ik_soft_start` of reach) is not idempotent, so a pin
// set where a softened ankle touched down was softened again and pulled the
// ankle a few mm off it, then let it creep back as the width eased out with the
// plant (2.1 mm of skate on the CMU fast_walk stop). This is the target whose
// softened image is `target` (the pre-image along root → target): a pinned
// ankle then lands on its pin exactly while the pin is within
// kPinExactReachFraction of the leg's softened range; beyond it the pre-image
// of that distance plus the excess, so the result stays continuous and
// increasing. No libm: the soft reach's e^−x is the springs' rational, inverted
// by Newton's method (a fixed count of steps).
vec3 pinned_reach_target(vec3 root, vec3 target, float reach, float width, float ik_soft_start);
inline constexpr float kPinExactReachFraction = 0.995f;

// smooth_feet's lowering for reach: a pinned ankle stays where it touched down
// while the clip's body moves on; where the clip lifts the heel before the leg
// would be straight (the retargeted CMU stops: the rear foot's ankle 0.886 m
// from the hip, reach 0.87 m) the pin fell out of reach and the IK dragged the
// planted foot (12-30 mm of skate). So the body is lowered as far as the
// farthest pinned ankle needs, to kPinnedReachFraction of its (soft) reach (the
// two-bone IK's soft_reach_start: past it the IK eases the reach in and the
// ankle leaves its pin), at
// most kMaxReachDropM; it follows a deeper need at once (the need is
// continuous: the pin is fixed and the body moves smoothly) and rises back
// through a critically damped spring of halflife kReachDropHalflifeS.
inline constexpr float kPinnedReachFraction = 0.98f;
inline constexpr float kMaxReachDropM = 0.1f;
inline constexpr float kReachDropHalflifeS = 0.1f;

// How far (m, in [0, cap]) a hip must come down for an ankle `target` to lie
// within `reach` of it: 0 when it already does; else the least drop that puts
// it on the sphere of that radius; where no drop does (the target farther than
// reach horizontally, or above the hip), the one that brings it nearest (the
// hip level with the target, 0 when it is above). Clamped to cap.
float reach_drop_needed(vec3 hip, vec3 target, float reach, float cap);

struct FootPlacementJob {
    FootPlacementState* state = nullptr;
    const FootPlacementRig* rig = nullptr;
    const Terrain* terrain = nullptr;
    std::uint8_t contacts = 0;     // the clip pose's contacts: bit 0 left, bit 1 right
    float dt = 0.0f;               // seconds since the last tick (0: place without advancing)
    float release_s = 0.15f;
    float terrain_rate = 10.0f;    // 1/s
    std::span<const int> parents;
    // In: the clip pose (locals) and its forward kinematics. Out: the placed pose, both.
    PoseSpans pose;
    // After placement, a foot whose ankle, toe or tip (add_foot_tips) is below
    // the ground under it is lifted (two-bone IK again, the foot's rotation kept)
    // until its lowest point is on the ground: no point of the foot penetrates.
    bool keep_above_ground = false;
    // Matching: motions continuous in time instead of the graph's blends. A pin
    // lets go through an inertialized offset (the ankle starts where and as fast
    // as it was, then the offset decays critically damped, halflife
    // release_s / 3) instead of a smoothstep lerp; and keep_above_ground's lift
    // is a critically damped spring toward the deepest the foot will be within
    // kLiftLookAheadS at its current horizontal velocity (rising before a riser
    // is reached, falling smoothly after), never below the depth it is at now,
    // and a free foot the lift has not raised in time is held back short of the
    // riser (kHoldMarginM) instead of snapping up; and a free foot's ground
    // follows a spring (kFootGroundHalflifeS), not the 3 m/s limit; and the
    // two-bone IK bends the knee toward the thigh's +Z, not toward the clip's knee;
    // and the ground normal a foot tilts to follows the one under it through a
    // critically damped spring (kTiltHalflifeS), so a crease does not snap it;
    // and the body is lowered for a pinned ankle out of reach (lower_for_reach).
    bool smooth_feet = false;

    // False without a state, rig or terrain, with an invalid rig (a toe or tip
    // joint neither −1 nor a joint included), a negative time
    // or rate, spans not of the skeleton's size, or parents out of order.
    bool validate() const;
    [[nodiscard]] bool run() const;

private:
    void solve_leg(const FootPlacementLeg& leg, vec3 target, quat foot_world, vec3 forward) const;
    vec3 thigh_pole(const FootPlacementLeg& leg, vec3 forward) const;
    float foot_depth(const FootPlacementLeg& leg, vec3 shift) const;
    bool lift_feet_above_ground(vec3 forward) const;
    void lower_for_reach(const vec3 (&targets)[2]) const;
    float soft_reach_width(int leg) const;
    float leg_reach(const FootPlacementLeg& leg) const;
    float pinned_weight(int leg) const;
    vec3 smooth_lift(FootPin& pin, const FootPlacementLeg& leg) const;
    vec3 pin_target(FootPin& pin, vec3 free, vec3 clip_velocity, bool let_go) const;
    vec3 tilt_normal(FootPin& pin, vec3 ground_normal) const;
};

}  // namespace marionette
