#include "runtime/anim/foot_placement.hpp"

#include <cmath>

#include "runtime/anim/skeleton.hpp"
#include "runtime/anim/two_bone_ik.hpp"

namespace marionette {

namespace {
float clamp01(float v) { return v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v); }
float smoothstep(float u) { return u * u * (3.0f - 2.0f * u); }
float length_of(vec3 v) { return std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z); }
vec3 unit_or(vec3 v, vec3 fallback) {
    const float n = length_of(v);
    return n > 1e-6f ? v / n : fallback;
}
// e^(−x) for x ≥ 0 as the rational 1 / (1 + x + 0.48x² + 0.235x³): no libm transcendental.
float negexp(float x) { return 1.0f / (1.0f + x + 0.48f * x * x + 0.235f * x * x * x); }
constexpr float kLn2 = 0.69314718f;
// One step of a critically damped spring of `halflife` carrying x (rate v) toward goal.
void damp_toward(float& x, float& v, float goal, float halflife, float dt) {
    const float y = 2.0f * kLn2 / halflife;
    const float j0 = x - goal, j1 = v + j0 * y, e = negexp(y * dt);
    x = e * (j0 + j1 * dt) + goal;
    v = e * (v - j1 * y * dt);
}
}  // namespace

void add_foot_tips(FootPlacementRig& rig, std::span<const int> parents, std::span<const int> end_site_parents,
                   std::span<const vec3> end_site_offsets, float metres_per_unit) {
    const int count = static_cast<int>(parents.size());
    for (FootPlacementLeg& leg : rig.legs) {
        leg.toe = leg.tip_parent = -1;
        if (leg.ankle < 0) continue;
        for (int j = 0; j < count && leg.toe < 0; ++j)
            if (parents[static_cast<size_t>(j)] == leg.ankle) leg.toe = j;
        const int last = leg.toe >= 0 ? leg.toe : leg.ankle;
        for (size_t e = 0; e < end_site_parents.size() && e < end_site_offsets.size(); ++e)
            if (end_site_parents[e] == last) {
                leg.tip_parent = last;
                leg.tip = end_site_offsets[e] * metres_per_unit;
                break;
            }
    }
}

FootPlacementRig make_foot_placement_rig(std::span<const int> parents, int left_ankle, int right_ankle) {
    FootPlacementRig rig;
    const int count = static_cast<int>(parents.size());
    for (int j = 0; j < count; ++j)
        if (parents[static_cast<size_t>(j)] == kNoParent) {
            rig.root = j;
            break;
        }
    const int ankles[2] = {left_ankle, right_ankle};
    rig.valid = true;
    for (int i = 0; i < 2; ++i) {
        FootPlacementLeg& leg = rig.legs[static_cast<size_t>(i)];
        const int ankle = ankles[i];
        const int knee = ankle >= 0 && ankle < count ? parents[static_cast<size_t>(ankle)] : kNoParent;
        const int hip = knee >= 0 ? parents[static_cast<size_t>(knee)] : kNoParent;
        if (hip < 0 || hip == rig.root) {
            rig.valid = false;
            continue;
        }
        leg = {hip, knee, ankle};
    }
    return rig;
}

// smooth_feet's knee pole: the thigh's frame's +Z (the skeleton's forward in
// its rest pose, so the kneecap's direction), which turns with the thigh and
// stays defined however straight the leg is.
vec3 FootPlacementJob::thigh_pole(const FootPlacementLeg& leg, vec3 forward) const {
    return unit_or(quat_rotate(pose.model_rotations[static_cast<size_t>(leg.hip)], vec3(0.0f, 0.0f, 1.0f)), forward);
}

// The two-bone IK of one leg toward `target` (the ankle, world), the foot
// turned to `foot_world`: the clip's thigh and shin are turned onto the solved
// bones (shortest arcs), so the skeleton's own segment frames and twist are kept.
// A degenerate leg (zero length, non-finite target) keeps its pose.
void FootPlacementJob::solve_leg(const FootPlacementLeg& leg, vec3 target, quat foot_world, vec3 forward) const {
    const vec3 up(0.0f, 1.0f, 0.0f);
    const size_t hip = static_cast<size_t>(leg.hip), knee = static_cast<size_t>(leg.knee), ankle = static_cast<size_t>(leg.ankle);
    const vec3 h = pose.model_positions[hip], k = pose.model_positions[knee], a = pose.model_positions[ankle];
    TwoBoneIkJob ik;
    ik.root = h;
    ik.target = target;
    // smooth_feet: a free leg's reach is soft (kSoftReachFraction), eased out
    // as the foot plants; a pinned foot aims at its pin's pre-image through the
    // softening, so it lands on the pin (eased out again as it lets go).
    if (smooth_feet) {
        const int i = static_cast<int>(&leg - rig->legs.data());
        const float width = soft_reach_width(i), pinned = pinned_weight(i);
        const float reach = leg_reach(leg);
        vec3 aim = target;
        if (pinned > 0.0f) aim = target + (pinned_reach_target(h, target, reach, width, ik.soft_reach_start) - target) * pinned;
        ik.target = width > 0.0f ? soften_reach(h, aim, reach, width) : aim;
    }
    // graph_feet: the clip's knee off the hip–ankle midpoint. smooth_feet (matching):
    // the thigh's +Z, since the clip's knee off the midpoint is ill-conditioned on a
    // nearly straight leg and swung the knee about the hip–ankle axis by up to 77°
    // in a tick on the retargeted CMU clips (40,000 °/s).
    ik.pole = smooth_feet ? thigh_pole(leg, forward) : unit_or(k - 0.5f * (h + a), forward);
    ik.upper_length = length_of(pose.local_translations[knee]);
    ik.lower_length = length_of(pose.local_translations[ankle]);
    TwoBoneIkResult r;
    ik.result = &r;
    if (!ik.run()) return;
    const quat turn_upper = quat_from_to(unit_or(k - h, -up), unit_or(r.mid - h, -up));
    const vec3 lower_before = quat_rotate(turn_upper, unit_or(a - k, -up));
    const quat turn_lower = quat_from_to(lower_before, unit_or(r.end - r.mid, -up));
    const quat hip_world = quat_normalize(quat_mul(turn_upper, pose.model_rotations[hip]));
    const quat knee_world = quat_normalize(quat_mul(turn_lower, quat_mul(turn_upper, pose.model_rotations[knee])));
    const int hip_parent = parents[hip];
    const quat parent_world = hip_parent >= 0 ? pose.model_rotations[static_cast<size_t>(hip_parent)] : quat_identity();
    pose.local_rotations[hip] = quat_normalize(quat_mul(quat_conjugate(parent_world), hip_world));
    pose.local_rotations[knee] = quat_normalize(quat_mul(quat_conjugate(hip_world), knee_world));
    pose.local_rotations[ankle] = quat_normalize(quat_mul(quat_conjugate(knee_world), foot_world));
}

// How far (m) the foot's lowest point (ankle, toe, tip) is below the ground under it; ≤ 0: none is.
// `shift` moves every point (the foot's predicted motion).
float FootPlacementJob::foot_depth(const FootPlacementLeg& leg, vec3 shift) const {
    vec3 points[3];
    int count = 0;
    points[count++] = pose.model_positions[static_cast<size_t>(leg.ankle)];
    if (leg.toe >= 0) points[count++] = pose.model_positions[static_cast<size_t>(leg.toe)];
    if (leg.tip_parent >= 0) {
        const size_t p = static_cast<size_t>(leg.tip_parent);
        points[count++] = pose.model_positions[p] + quat_rotate(pose.model_rotations[p], leg.tip);
    }
    float depth = -1e30f;
    for (int i = 0; i < count; ++i) {
        const vec3 q = points[i] + shift;
        const float d = query_ground(*terrain, q.x, q.z).height - q.y;
        depth = d > depth ? d : depth;
    }
    return depth;
}

// keep_above_ground: each foot below the ground is lifted by its depth (its
// rotation kept, so every point rises as much). True when a leg moved (the
// caller runs forward kinematics again).
bool FootPlacementJob::lift_feet_above_ground(vec3 forward) const {
    bool moved = false;
    for (const FootPlacementLeg& leg : rig->legs) {
        const vec3 shift = smooth_feet ? smooth_lift(state->feet[static_cast<size_t>(&leg - rig->legs.data())], leg)
                                       : vec3(0.0f, foot_depth(leg, vec3(0.0f)), 0.0f);
        if (!(shift.y > 0.0f) && shift.x == 0.0f && shift.z == 0.0f) continue;
        const size_t ankle = static_cast<size_t>(leg.ankle);
        const vec3 lift(shift.x, shift.y > 0.0f ? shift.y : 0.0f, shift.z);
        solve_leg(leg, pose.model_positions[ankle] + lift, pose.model_rotations[ankle], forward);
        moved = true;
    }
    return moved;
}

// smooth_feet's lift and hold of one free foot: the shift (m) its ankle is
// moved by, a horizontal hold-back plus a lift ≥ 0.
//   The lift is a spring toward the deepest the foot is now or will be within
//   kLiftLookAheadS, moving at its current horizontal velocity (not its
//   vertical one: the foot's own ground easing up must not hide a riser ahead).
//   The hold: where the lift has not yet reached the depth the foot would be at
//   now (its toes would cross into a riser), the foot is held back along the
//   way it came, as little as keeps it out of the riser plus kHoldMarginM, and
//   the held-back offset then decays (critically damped, kHoldHalflifeS) so the
//   foot catches up with the clip's once the lift clears the step. Only where
//   even last tick's place is too deep does the lift snap to the depth (the
//   floor, so no point penetrates). A pinned foot is never held back.
vec3 FootPlacementJob::smooth_lift(FootPin& pin, const FootPlacementLeg& leg) const {
    const vec3 a = pose.model_positions[static_cast<size_t>(leg.ankle)];
    const bool advance = state->started && dt > 0.0f;
    const bool free = state->started && pin.contact != 1;
    const vec3 clip_previous = pin.unlifted_previous - pin.hold_offset;  // the clip's ankle last tick
    const vec3 previous = pin.unlifted_previous;                         // where the ankle was put last tick, before the lift
    if (!free) pin.hold_offset = pin.hold_velocity = vec3(0.0f);
    else if (advance) {
        damp_toward(pin.hold_offset.x, pin.hold_velocity.x, 0.0f, kHoldHalflifeS, dt);
        damp_toward(pin.hold_offset.z, pin.hold_velocity.z, 0.0f, kHoldHalflifeS, dt);
    }
    vec3 velocity = advance ? (a + pin.hold_offset - previous) / dt : vec3(0.0f);
    velocity.y = 0.0f;
    float now = foot_depth(leg, pin.hold_offset);
    float goal = now > 0.0f ? now : 0.0f;
    for (int k = 1; k <= 3; ++k) {
        const float ahead = foot_depth(leg, pin.hold_offset + velocity * (kLiftLookAheadS * static_cast<float>(k) / 3.0f));
        goal = ahead > goal ? ahead : goal;
    }
    if (!state->started) pin.lift = goal, pin.lift_velocity = 0.0f;
    else if (advance) damp_toward(pin.lift, pin.lift_velocity, goal, kLiftHalflifeS, dt);
    if (free && advance && pin.lift < now) {
        vec3 back = previous - (a + pin.hold_offset);
        back.y = 0.0f;
        if (foot_depth(leg, pin.hold_offset + back) <= pin.lift) {
            // Bisect for the least fraction of the way back that keeps the foot
            // out (the depth along it is a step function: a riser's edge).
            float inside = 0.0f, outside = 1.0f;
            for (int it = 0; it < 12; ++it) {
                const float mid = 0.5f * (inside + outside);
                if (foot_depth(leg, pin.hold_offset + back * mid) <= pin.lift) outside = mid;
                else inside = mid;
            }
            const float span = std::sqrt(back.x * back.x + back.z * back.z);
            const float fraction = span > kHoldMarginM ? outside + kHoldMarginM / span : 1.0f;
            pin.hold_offset += back * (fraction < 1.0f ? fraction : 1.0f);
            // Held, the foot is at rest: the offset's rate cancels the clip ankle's.
            pin.hold_velocity = vec3(-(a.x - clip_previous.x) / dt, 0.0f, -(a.z - clip_previous.z) / dt);
            now = foot_depth(leg, pin.hold_offset);
        }
    }
    const float floor = now > 0.0f ? now : 0.0f;
    if (pin.lift < floor) {
        pin.lift = floor;
        if (pin.lift_velocity < 0.0f) pin.lift_velocity = 0.0f;
    }
    pin.unlifted_previous = a + pin.hold_offset;
    return pin.hold_offset + vec3(0.0f, pin.lift, 0.0f);
}

// smooth_feet's ankle target: the pin while pinned; else the clip's ankle plus
// an offset that starts, when the pin lets go, at (pin − clip) with the clip's
// velocity cancelled, and decays critically damped (halflife release_s / 3).
vec3 FootPlacementJob::pin_target(FootPin& pin, vec3 free, vec3 clip_velocity, bool let_go) const {
    if (pin.contact == 1 || !state->started) {
        pin.release_offset = pin.release_velocity = vec3(0.0f);
        return pin.contact == 1 ? pin.pin : free;
    }
    if (let_go) {
        pin.release_offset = pin.pin - free;
        pin.release_velocity = -clip_velocity;
    }
    if (dt > 0.0f) {
        const float halflife = release_s > 0.0f ? release_s / 3.0f : 1e-3f;
        damp_toward(pin.release_offset.x, pin.release_velocity.x, 0.0f, halflife, dt);
        damp_toward(pin.release_offset.y, pin.release_velocity.y, 0.0f, halflife, dt);
        damp_toward(pin.release_offset.z, pin.release_velocity.z, 0.0f, halflife, dt);
    }
    return free + pin.release_offset;
}

// smooth_feet's soft-reach width (m) for leg i: kSoftReachFraction of the leg,
// eased out as the foot plants; 0 without smooth_feet.
float FootPlacementJob::soft_reach_width(int i) const {
    if (!smooth_feet) return 0.0f;
    return kSoftReachFraction * (1.0f - smoothstep(state->feet[static_cast<size_t>(i)].plant)) *
           leg_reach(rig->legs[static_cast<size_t>(i)]);
}

// The leg's length: thigh plus shin (the pose's knee and ankle offsets).
float FootPlacementJob::leg_reach(const FootPlacementLeg& leg) const {
    return length_of(pose.local_translations[static_cast<size_t>(leg.knee)]) +
           length_of(pose.local_translations[static_cast<size_t>(leg.ankle)]);
}

// 1 while leg i is pinned, eased out (smoothstep) over release_s after it lets go.
float FootPlacementJob::pinned_weight(int i) const {
    const FootPin& pin = state->feet[static_cast<size_t>(i)];
    return pin.contact == 1 ? 1.0f : 1.0f - smoothstep(clamp01(pin.release));
}

namespace {
// The distance d whose soften_reach image is `distance` (start = reach − width).
float unsoften_distance(float distance, float reach, float width) {
    const float start = reach - width;
    if (!(width > 0.0f) || !(distance > start)) return distance;
    // negexp(x) = 1 − u  ⇔  x + 0.48x² + 0.235x³ = u / (1 − u): increasing and
    // convex for x ≥ 0, so Newton's method from x = u / (1 − u) (at or right of
    // the root) descends onto it without overshooting.
    const float u = (distance - start) / width;
    const float c = u / (1.0f - u);
    float x = c;
    for (int step = 0; step < 24; ++step) {
        const float p = x + 0.48f * x * x + 0.235f * x * x * x - c;
        const float slope = 1.0f + 0.96f * x + 0.705f * x * x;
        x -= p / slope;
    }
    return start + width * x;
}

// The distance d whose two-bone IK soft-reach image is `distance`
// (d' = s + r·x/(x + r), x = d − s, s = soft_start·full, r = full − s).
float unsoften_ik_distance(float distance, float full, float soft_start) {
    const float s = soft_start * full, r = full - s;
    if (!(distance > s) || !(r > 0.0f)) return distance;
    const float x = distance - s;
    return s + r * x / (r - x);
}
}  // namespace

vec3 pinned_reach_target(vec3 root, vec3 target, float reach, float width, float ik_soft_start) {
    const vec3 d = target - root;
    const float distance = length_of(d);
    if (!(distance > 0.0f) || !(reach > 0.0f)) return target;
    // The softened range: soften_reach stays short of reach, and the IK's soft
    // reach maps reach to s + r/2 (s = ik_soft_start·reach, r = reach − s).
    const float top = width > 0.0f ? reach * ik_soft_start + 0.5f * (reach - reach * ik_soft_start) : reach;
    const float exact = kPinExactReachFraction * top;
    const float inside = distance < exact ? distance : exact;
    const float before_ik = unsoften_ik_distance(inside, reach, ik_soft_start);
    const float aimed = unsoften_distance(before_ik, reach, width) + (distance - inside);
    return root + d * (aimed / distance);
}

float reach_drop_needed(vec3 hip, vec3 target, float reach, float cap) {
    const vec3 d = target - hip;
    const float horizontal2 = d.x * d.x + d.z * d.z;
    // Out of reach however far the hip comes down: as near as it gets, level with the target.
    const float drop = reach > 0.0f && horizontal2 < reach * reach ? -d.y - std::sqrt(reach * reach - horizontal2) : -d.y;
    return drop > cap ? cap : (drop > 0.0f ? drop : 0.0f);
}

// smooth_feet: the body lowered (kMaxReachDropM at most) so every pinned
// ankle's target lies within its leg's reach; see kPinnedReachFraction.
void FootPlacementJob::lower_for_reach(const vec3 (&targets)[2]) const {
    FootPlacementState& s = *state;
    float need = 0.0f;
    for (int i = 0; i < 2; ++i) {
        if (s.feet[static_cast<size_t>(i)].contact != 1) continue;
        const FootPlacementLeg& leg = rig->legs[static_cast<size_t>(i)];
        const float l = (leg_reach(leg) - soft_reach_width(i)) * kPinnedReachFraction;
        // Eased in as the foot plants: a pin starts wherever the foot touched
        // down, so its need can start at any size (taken at once, it dropped
        // the body in a tick and turned the shins at up to 2,034 °/s).
        const float n = reach_drop_needed(pose.model_positions[static_cast<size_t>(leg.hip)], targets[i], l, kMaxReachDropM) *
                        smoothstep(s.feet[static_cast<size_t>(i)].plant);
        need = n > need ? n : need;
    }
    if (!s.started || need >= s.reach_drop) {
        s.reach_drop = need;
        s.reach_drop_velocity = 0.0f;
    } else if (dt > 0.0f) {
        damp_toward(s.reach_drop, s.reach_drop_velocity, need, kReachDropHalflifeS, dt);
        if (s.reach_drop < need) {  // the spring undershot a need that is still there
            s.reach_drop = need;
            s.reach_drop_velocity = 0.0f;
        }
    }
    if (!(s.reach_drop > 0.0f)) return;
    pose.local_translations[static_cast<size_t>(rig->root)].y -= s.reach_drop;
    for (vec3& p : pose.model_positions) p.y -= s.reach_drop;
}

vec3 soften_reach(vec3 root, vec3 target, float reach, float width) {
    const vec3 d = target - root;
    const float distance = length_of(d);
    const float start = reach - width;
    if (!(width > 0.0f) || !(distance > start) || !(distance > 0.0f)) return target;
    const float eased = start + width * (1.0f - negexp((distance - start) / width));
    return root + d * (eased / distance);
}

vec3 step_tilt_normal(vec3& normal, vec3& velocity, vec3 ground_normal, float dt) {
    if (dt > 0.0f) {
        damp_toward(normal.x, velocity.x, ground_normal.x, kTiltHalflifeS, dt);
        damp_toward(normal.y, velocity.y, ground_normal.y, kTiltHalflifeS, dt);
        damp_toward(normal.z, velocity.z, ground_normal.z, kTiltHalflifeS, dt);
    }
    return unit_or(normal, ground_normal);
}

// smooth_feet's tilt normal: step_tilt_normal toward the ground's normal under
// the foot; it starts on that normal. The ground's normal jumps at a slope's
// edge; this does not.
vec3 FootPlacementJob::tilt_normal(FootPin& pin, vec3 ground_normal) const {
    if (!state->started) {
        pin.tilt_normal = ground_normal;
        pin.tilt_normal_velocity = vec3(0.0f);
        return unit_or(pin.tilt_normal, ground_normal);
    }
    return step_tilt_normal(pin.tilt_normal, pin.tilt_normal_velocity, ground_normal, dt);
}

bool FootPlacementJob::validate() const {
    const size_t n = parents.size();
    if (!state || !rig || !terrain || !rig->valid || !(dt >= 0.0f) || !(release_s >= 0.0f) || !(terrain_rate > 0.0f)) return false;
    if (!pose.has_joints(n) || !parents_in_topological_order(parents)) return false;
    const auto is_joint = [n](std::int32_t j) { return j >= 0 && static_cast<size_t>(j) < n; };
    const auto none_or_joint = [&](std::int32_t j) { return j == -1 || is_joint(j); };
    for (const FootPlacementLeg& leg : rig->legs)
        if (!is_joint(leg.hip) || !is_joint(leg.knee) || !is_joint(leg.ankle) || !none_or_joint(leg.toe) ||
            !none_or_joint(leg.tip_parent))
            return false;
    return is_joint(rig->root);
}

bool FootPlacementJob::run() const {
    if (!validate()) return false;
    FootPlacementState& s = *state;
    const vec3 up(0.0f, 1.0f, 0.0f);

    // Each foot's ground: under it, or higher just ahead of it; eased, so a step
    // up lifts the foot over a few ticks instead of at once.
    GroundSample sample[2];
    bool slow[2];
    vec3 clip_velocity[2];
    for (int i = 0; i < 2; ++i) {
        FootPin& pin = s.feet[static_cast<size_t>(i)];
        const vec3 a = pose.model_positions[static_cast<size_t>(rig->legs[static_cast<size_t>(i)].ankle)];
        sample[i] = query_ground(*terrain, a.x, a.z);
        const vec3 moved = s.started ? a - pin.clip_previous : vec3(0.0f);
        const float step = std::sqrt(moved.x * moved.x + moved.z * moved.z);
        slow[i] = !(dt > 0.0f) || step <= kPinMaxSpeed * dt;
        clip_velocity[i] = dt > 0.0f ? moved / dt : vec3(0.0f);
        float wanted = sample[i].height;
        if (step > 1e-6f) {
            const float ahead = max_height_along(*terrain, a.x, a.z, a.x + moved.x / step * kFootLookAheadM,
                                                 a.z + moved.z / step * kFootLookAheadM, 0.05f);
            wanted = ahead > wanted ? ahead : wanted;
        }
        if (!s.started || pin.contact == 1) {
            pin.ground = sample[i].height;
            pin.ground_velocity = 0.0f;
        } else if (smooth_feet) {
            // A spring, not the rate limit: the foot's ground starts and stops
            // moving smoothly (the limit's 0 → 3 m/s in one tick turned the knee
            // up to 2,113 °/s); a riser it has not risen to in time is the hold's.
            if (dt > 0.0f) damp_toward(pin.ground, pin.ground_velocity, wanted, kFootGroundHalflifeS, dt);
        } else {
            const float limit = kFootGroundSpeed * dt;
            const float change = wanted - pin.ground;
            pin.ground += change > limit ? limit : (change < -limit ? -limit : change);
        }
        pin.clip_previous = a;
    }
    // The body follows the lower of the two feet's grounds.
    const float lowest = s.feet[0].ground < s.feet[1].ground ? s.feet[0].ground : s.feet[1].ground;
    if (!s.started) s.body_offset = lowest;
    else s.body_offset += (lowest - s.body_offset) * clamp01(terrain_rate * dt);
    const size_t root = static_cast<size_t>(rig->root);
    pose.local_translations[root].y += s.body_offset;
    for (vec3& p : pose.model_positions) p.y += s.body_offset;

    const vec3 forward = quat_rotate(pose.model_rotations[root], vec3(0.0f, 0.0f, 1.0f));
    vec3 targets[2];
    quat foot_world[2];
    for (int i = 0; i < 2; ++i) {
        const FootPlacementLeg& leg = rig->legs[static_cast<size_t>(i)];
        FootPin& pin = s.feet[static_cast<size_t>(i)];
        const size_t ankle = static_cast<size_t>(leg.ankle);
        // The clip's ankle, as high above the ground under it as it was above its flat floor.
        const vec3 free = pose.model_positions[ankle] + vec3(0.0f, pin.ground - s.body_offset, 0.0f);
        const bool contact = ((contacts >> i) & 1u) && slow[i];
        const bool was_pinned = pin.contact == 1;
        // smooth_feet lifts after placement, so its pins are where the ankle was placed before the lift.
        const vec3 placed = smooth_feet && keep_above_ground ? pin.unlifted_previous : pin.placed;
        if (contact && pin.contact == 0) {
            pin.pin = s.started ? placed : free;
            pin.contact = 1;
        } else if (!contact && pin.contact != 0) {
            pin.contact = 0;
            pin.release = 0.0f;
        }
        if (pin.contact == 1) {
            const float sx = pin.pin.x - free.x, sz = pin.pin.z - free.z;
            if (sx * sx + sz * sz > kMaxPinSlipM * kMaxPinSlipM) {
                pin.contact = 2;
                pin.pin = placed;
                pin.release = 0.0f;
            }
        }
        if (pin.contact == 1) pin.release = 0.0f;
        else pin.release = release_s > 0.0f ? clamp01(pin.release + dt / release_s) : 1.0f;
        if (!s.started) pin.release = pin.contact == 1 ? 0.0f : 1.0f;
        // The tilt to the ground eases in and out over release_s as well: a foot
        // landing on a slope must not snap to it.
        const float plant_step = release_s > 0.0f ? dt / release_s : 1.0f;
        pin.plant = !s.started ? (pin.contact == 1 ? 1.0f : 0.0f)
                               : clamp01(pin.plant + (pin.contact == 1 ? plant_step : -plant_step));
        const vec3 target = smooth_feet ? pin_target(pin, free, clip_velocity[i], was_pinned && pin.contact != 1)
                                        : lerp(pin.pin, free, smoothstep(pin.release));

        // A planted foot lies on the ground's slope; a lifted one keeps the clip's.
        // (The normal under the target, not under the clip's foot: a pinned foot
        // must not tilt because the clip's foot slid over a slope's edge.)
        const vec3 ground_normal = query_ground(*terrain, target.x, target.z).normal;
        const vec3 normal = smooth_feet ? tilt_normal(pin, ground_normal) : ground_normal;
        const quat tilt = quat_slerp(quat_identity(), quat_from_to(up, normal), smoothstep(pin.plant));
        targets[i] = target;
        foot_world[i] = quat_normalize(quat_mul(tilt, pose.model_rotations[ankle]));
    }
    if (smooth_feet) lower_for_reach(targets);
    for (int i = 0; i < 2; ++i) solve_leg(rig->legs[static_cast<size_t>(i)], targets[i], foot_world[i], forward);
    // Cannot fail: validate() checked the sizes and the order FK needs.
    if (!LocalToModelJob{parents, pose.local(), pose.model()}.run()) return false;
    if (keep_above_ground && lift_feet_above_ground(forward) &&
        !LocalToModelJob{parents, pose.local(), pose.model()}.run())
        return false;
    for (int i = 0; i < 2; ++i)
        s.feet[static_cast<size_t>(i)].placed = pose.model_positions[static_cast<size_t>(rig->legs[static_cast<size_t>(i)].ankle)];
    s.started = 1;
    return true;
}

}  // namespace marionette
