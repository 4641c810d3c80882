#include "runtime/gait/gait.hpp"

#include <cmath>
#include <cstring>

#include "runtime/gait/puppet.hpp"
#include "runtime/gait/steering.hpp"
#include "runtime/ground/obstacles.hpp"
#include "runtime/anim/local_to_model.hpp"
#include "runtime/anim/skeleton.hpp"
#include "runtime/anim/two_bone_ik.hpp"

namespace marionette {

namespace {

float dot3(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
vec3 cross3(vec3 a, vec3 b) { return vec3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x); }
float length3(vec3 v) { return std::sqrt(dot3(v, v)); }
vec3 normalize3(vec3 v, vec3 fallback) {
    const float n = length3(v);
    return n > 1e-9f ? v / n : fallback;
}
float clampf(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }
float maxf(float a, float b) { return a > b ? a : b; }
float minf(float a, float b) { return a < b ? a : b; }
float frac(float v) { return v - std::floor(v); }
float horizontal_distance(vec3 a, vec3 b) {
    const float dx = a.x - b.x, dz = a.z - b.z;
    return std::sqrt(dx * dx + dz * dz);
}
// Exponential approach without exp: the fraction min(1, rate·dt) per tick.
float approach(float value, float target, float rate, float dt) { return value + (target - value) * minf(1.0f, rate * dt); }
// v limited to [−limit, limit] (limit ≥ 0).
double clamp_magnitude(double v, double limit) { return v > limit ? limit : (v < -limit ? -limit : v); }

struct HeadingFrame {
    vec3 forward;  // (sin h, 0, cos h)
    vec3 left;     // (cos h, 0, −sin h): the puppet's +X
};
HeadingFrame heading_frame(double heading) {
    double s = 0.0, c = 0.0;
    det::sin_cos(heading, s, c);
    return {vec3(static_cast<float>(s), 0.0f, static_cast<float>(c)), vec3(static_cast<float>(c), 0.0f, static_cast<float>(-s))};
}
float side_sign(int foot) { return foot == 0 ? 1.0f : -1.0f; }  // left foot is on +X

}  // namespace

// Prototype → Hermite keys. Tangents from the neighbours (Catmull–Rom on uneven
// phases); a looping path wraps them, an open one (swing) starts and ends at rest.
int build_prototype_keys(const SplinePrototype& p, bool loops, std::array<HermiteKey, kMaxPrototypeKeys>& out) {
    const int n = p.count < 0 ? 0 : (p.count > kMaxPrototypeKeys ? kMaxPrototypeKeys : p.count);
    for (int i = 0; i < n; ++i) {
        const PrototypeKey& k = p.keys[static_cast<std::size_t>(i)];
        out[static_cast<std::size_t>(i)] = {k.phase, vec3(k.x, k.y, k.z), vec3(0.0f)};
    }
    for (int i = 1; i + 1 < n; ++i) {
        const HermiteKey& a = out[static_cast<std::size_t>(i - 1)];
        const HermiteKey& b = out[static_cast<std::size_t>(i + 1)];
        const float span = b.time - a.time;
        if (span > 0.0f) out[static_cast<std::size_t>(i)].tangent = (b.position - a.position) / span;
    }
    if (loops && n >= 3) {
        const HermiteKey& second = out[1];
        const HermiteKey& before_last = out[static_cast<std::size_t>(n - 2)];
        const float span = (second.time - out[0].time) + (out[static_cast<std::size_t>(n - 1)].time - before_last.time);
        const vec3 t = span > 0.0f ? (second.position - before_last.position) / span : vec3(0.0f);
        out[0].tangent = t;
        out[static_cast<std::size_t>(n - 1)].tangent = t;
    }
    return n;
}

namespace {

vec3 eval_keys(const std::array<HermiteKey, kMaxPrototypeKeys>& keys, int count, float phase) {
    return sample_hermite_position(std::span<const HermiteKey>(keys.data(), static_cast<std::size_t>(count)), phase);
}

// The walk/run blend of two prototype samples, lerp(walk, run, blend). At
// blend 0 (every walk below run_threshold − 0.3 m/s) that is walk + (run −
// walk)·0, which is walk itself unless a component of walk is ±0 (then the sign
// of run − walk decides the zero's sign): the run prototype is evaluated only
// then, and the result is the same bits either way.
bool has_zero(vec3 v) { return v.x == 0.0f || v.y == 0.0f || v.z == 0.0f; }
template <class Run>
vec3 blend_with(vec3 walk, float blend, const Run& run) {
    if (blend == 0.0f && !has_zero(walk)) return walk;
    return lerp(walk, run(), blend);
}

vec3 blended_swing(const GaitRig& rig, float blend, float u) {
    return blend_with(eval_keys(rig.walk.swing_foot, rig.walk.swing_count, u), blend,
                      [&] { return eval_keys(rig.run.swing_foot, rig.run.swing_count, u); });
}
vec3 blended_pelvis(const GaitRig& rig, float blend, float phase) {
    return blend_with(eval_keys(rig.walk.pelvis, rig.walk.pelvis_count, phase), blend,
                      [&] { return eval_keys(rig.run.pelvis, rig.run.pelvis_count, phase); });
}
// The hand path and its velocity (metres per cycle of phase).
HermiteSample blended_hand(const GaitRig& rig, float blend, float phase) {
    const HermiteSample walk = sample_hermite(std::span<const HermiteKey>(rig.walk.hand.data(), static_cast<std::size_t>(rig.walk.hand_count)), phase);
    if (blend == 0.0f && !has_zero(walk.position) && !has_zero(walk.velocity)) return walk;
    const HermiteSample run = sample_hermite(std::span<const HermiteKey>(rig.run.hand.data(), static_cast<std::size_t>(rig.run.hand_count)), phase);
    return {lerp(walk.position, run.position, blend), lerp(walk.velocity, run.velocity, blend)};
}

// Sole points relative to the ankle, in the foot frame: under the ankle, the
// ball of the foot (toe joint), the tip of the toes.
std::array<vec3, 3> sole_offsets(const GaitRig& rig) {
    return {vec3(0.0f, -rig.ankle_height, 0.0f), vec3(0.0f, -rig.ankle_height, rig.foot_length),
            vec3(0.0f, -rig.ankle_height, rig.foot_length + rig.toe_length)};
}

struct Placement {
    vec3 ankle;
    quat rotation;
    float ground;
    float misfit;  // how far the sole had to rise to clear its toes, or a riser just ahead is above it
};

// A foot fits the ground when its sole, from kHeelMarginM behind the ankle to
// kToeMarginM past the toe tip, lies on one surface (docs/gait.md): no heel or
// toe over an edge, no toe against a riser.
constexpr float kHeelMarginM = 0.015f;
constexpr float kToeMarginM = 0.025f;
constexpr float kEdgeDropM = 0.02f;      // ground this far below the sole plane is past an edge
constexpr float kFitTolerance = 0.004f;  // m of misfit a spot may have
constexpr float kSpotSearchStepM = 0.005f;
constexpr float kSettledM = 1e-4f;            // m: an idle root this close to the middle of its feet has settled
constexpr float kObstacleTopProbeM = 0.005f;  // m below a spot's ground: inside the box it stands on
constexpr int kObstacleSearchSteps = 20;      // spots tried between a spot on an obstacle and the walkable side
constexpr float kWallFootClearanceM = 0.06f;  // m a planted foot keeps from a wall's face (the swing swings out 1–3 cm)
constexpr int kRiseSearchSteps = 40;          // spots tried between a step that rises too far and the planted foot
constexpr float kMaxStrideRiseShare = 0.52f;  // of the leg: the most a step rises or drops from the planted foot (0.45 m)
constexpr int kSpotSearchSteps = 34;     // on each side: up to 17 cm along the heading

// A planted foot at (x, z): sole on the surface, aligned to the normal there and
// to `forward` (pitch and roll to the surface); raised just enough that no sole
// point is below the ground.
Placement place_foot(const Terrain& terrain, const GaitRig& rig, float x, float z, vec3 forward) {
    const GroundSample g = query_ground(terrain, x, z);
    const vec3 n = g.normal;
    const vec3 toes = normalize3(forward - n * dot3(forward, n), vec3(0.0f, 0.0f, 1.0f));
    const vec3 side = cross3(n, toes);
    const quat rotation = quat_from_axes(side, n, toes);
    const vec3 ankle = vec3(x, g.height, z) + n * rig.ankle_height;
    float lift = 0.0f;
    for (const vec3& o : sole_offsets(rig)) {
        const vec3 p = ankle + quat_rotate(rotation, o);
        lift = maxf(lift, query_ground(terrain, p.x, p.z).height - p.y);
    }
    // Misfit: how far the sole had to rise, ground rising above the sole plane
    // just past the toes or behind the heel (a riser the toes would kick at
    // lift-off, or the heel would be clipped against coming down), and ground
    // dropping away under the margins or the sole points (over an edge).
    float misfit = lift;
    const float tip = rig.foot_length + rig.toe_length;
    for (float along : {-kHeelMarginM, 0.0f, rig.foot_length, tip, tip + kToeMarginM}) {
        const vec3 p = ankle + quat_rotate(rotation, vec3(0.0f, -rig.ankle_height, along)) + vec3(0.0f, lift, 0.0f);
        const float above = query_ground(terrain, p.x, p.z).height - p.y;
        misfit = maxf(misfit, maxf(above - lift, -above - lift - kEdgeDropM));
    }
    return {ankle + vec3(0.0f, lift, 0.0f), rotation, g.height + lift, misfit};
}

// The nearest spot along `forward` (within kSpotSearchSteps steps either way)
// where the whole sole rests on one surface, so feet never land straddling a
// step edge: on stairs this fits each step to the treads.
Placement place_foot_on_flat_spot(const Terrain& terrain, const GaitRig& rig, float x, float z, vec3 forward) {
    Placement best = place_foot(terrain, rig, x, z, forward);
    if (best.misfit < kFitTolerance) return best;
    for (int k = 1; k <= kSpotSearchSteps; ++k)
        for (float sign : {-1.0f, 1.0f}) {
            const float d = sign * kSpotSearchStepM * static_cast<float>(k);
            const Placement p = place_foot(terrain, rig, x + forward.x * d, z + forward.z * d, forward);
            if (p.misfit < kFitTolerance) return p;
            if (p.misfit < best.misfit) best = p;
        }
    return best;
}

float step_duration(const GaitConfig& c, float speed) {
    if (speed < 0.05f) return c.max_step_duration;
    return clampf(c.step_length_multiplier / std::sqrt(speed), c.min_step_duration, c.max_step_duration);
}

bool running(const GaitConfig& c, float speed) { return speed > c.run_threshold; }
constexpr float kMaxMeanSwingSpeed = 4.0f;  // m/s: a phase-driven swing takes at least its travel over this
// A walk's swing covers the stride, speed × cycle, in (1 − duty) of the cycle:
// its mean horizontal speed is speed / (1 − duty), at walk_duty 0.58 over
// kMaxMeanSwingSpeed above 1.68 m/s. Those swings were held to that speed and
// landed late, and the planted foot behind held the root (sweep case 7-0551, a
// 1.89 m/s walk down a 23° ramp, 2.2 % slow). A fast walk's duty shrinks so its
// swings keep within kWalkSwingSpeedShare of that speed (the rest is margin for
// the path's climb and curve), never below 0.5: a walk keeps a foot down.
constexpr float kWalkSwingSpeedShare = 0.9f;
float duty_for(const GaitConfig& c, float speed) {
    if (running(c, speed)) return c.run_duty;
    return maxf(0.5f, minf(c.walk_duty, 1.0f - speed / (kWalkSwingSpeedShare * kMaxMeanSwingSpeed)));
}

float foot_phase(float cycle_phase, int foot) { return frac(cycle_phase - (foot == 0 ? 0.0f : 0.5f)); }

// The foot's rotation at step fraction s, as the swing path's clearance keys
// see it (build_swing_path). The toes keep their lift-off direction for the
// first kHoldRotationShare of the step and reach their landing direction
// kHoldRotationShare before its end, so a foot planted beside a riser lifts
// before its toes sweep toward it (the path's clearance floor starts at its
// second key). The foot is posed by posed_swing_rotation: the same holds, the
// turn between them even in time.
constexpr float kHoldRotationShare = 0.1f;
// Beside a wall a swing may turn its foot over the first or the second half of
// the step instead (FootState::turn_order, set by begin_swing).
struct TurnShares {
    float from, to;
};
TurnShares turn_shares(const FootState& f) {
    if (f.turn_order < 0) return {kHoldRotationShare, 0.5f};
    if (f.turn_order > 0) return {0.5f, 1.0f - kHoldRotationShare};
    return {kHoldRotationShare, 1.0f - kHoldRotationShare};
}
quat swing_rotation(const FootState& f, float s) {
    if (f.turn_order != 0) {
        const TurnShares t = turn_shares(f);
        return quat_slerp(f.start_rotation, f.target_rotation, clampf((s - t.from) / (t.to - t.from), 0.0f, 1.0f));
    }
    const float turn = clampf((s - kHoldRotationShare) / (1.0f - 2.0f * kHoldRotationShare), 0.0f, 1.0f);
    return quat_slerp(f.start_rotation, f.target_rotation, turn);
}

// The foot's rotation at swing progress u, as it is posed: the same turn
// spread evenly over time between the progress where the step fraction passes
// kHoldRotationShare and where it passes 1 - kHoldRotationShare (gait16). By
// the step fraction (swing_rotation), the turn went at the fraction's speed,
// 3-4 times its mean mid-swing: an 86° turn in a 0.3 s step spun the foot at
// 1,230 °/s (sweep case 7-0613). The path's clearance keys still use
// swing_rotation: both hold the same rotations up to the window's start and
// from its end, where the foot is near the ground.
quat posed_swing_rotation(const FootState& f, float u) {
    const float span = f.turn_to - f.turn_from;
    const float turn = span > 1e-4f ? clampf((u - f.turn_from) / span, 0.0f, 1.0f) : (u >= f.turn_from ? 1.0f : 0.0f);
    return quat_slerp(f.start_rotation, f.target_rotation, turn);
}

// Where key i of a swing path lies, as a fraction s of the step's horizontal
// distance: on the arc-length table's grid (kArcLengthIntervals), so every
// table interval lies inside one smooth segment and the length inversion is
// accurate there; the first and last three intervals are one grid step each,
// the rest two.
constexpr std::array<int, kSwingPathKeys> kKeyGrid = {0, 1, 2, 3, 5, 7, 9, 11, 13, 15, 17, 19, 21, 23, 25, 27, 29, 30, 31, 32};
static_assert(kKeyGrid[kSwingPathKeys - 1] == kArcLengthIntervals);
// Both key tables are computed once, at compile time, by the expressions the
// swing path evaluated per key and per tick before (an IEEE float division or
// subtraction gives the same bits at compile time as at run time).
constexpr std::array<float, kSwingPathKeys> kKeyFraction = [] {
    std::array<float, kSwingPathKeys> out{};
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = static_cast<float>(kKeyGrid[i]) / static_cast<float>(kArcLengthIntervals);
    return out;
}();
float key_fraction(int i) { return kKeyFraction[static_cast<std::size_t>(i)]; }
// How much of the step's horizontal distance key i has covered: none at the
// first two keys and all at the last two, so the foot lifts off straight up and
// sets down straight down (toes a few centimetres from a riser rise past its
// top before they move toward it; a heel comes down onto its tread, not across
// the edge behind it), evenly in between.
constexpr float key_reach_of(int i) {
    constexpr int n = kSwingPathKeys;
    if (i <= 1) return 0.0f;
    if (i >= n - 2) return 1.0f;
    return static_cast<float>(kKeyGrid[static_cast<std::size_t>(i)] - kKeyGrid[1]) /
           static_cast<float>(kKeyGrid[static_cast<std::size_t>(n - 2)] - kKeyGrid[1]);
}
constexpr std::array<float, kSwingPathKeys> kKeyReach = [] {
    std::array<float, kSwingPathKeys> out{};
    for (int i = 0; i < kSwingPathKeys; ++i) out[static_cast<std::size_t>(i)] = key_reach_of(i);
    return out;
}();
float key_reach(int i) { return kKeyReach[static_cast<std::size_t>(i)]; }
// Fritsch–Butland tangent at key i of values v over key_fraction: the harmonic
// mean of the neighbouring slopes, zero at a peak, a valley, a flat and both
// ends, so each segment stays between its two keys (no overshoot, no dip).
template <class Value>
float monotone_tangent(const Value& v, int i) {
    constexpr int n = kSwingPathKeys;
    if (i <= 0 || i + 1 >= n) return 0.0f;
    const std::size_t k = static_cast<std::size_t>(i);
    const float s = key_fraction(i);
    const float before = (v(k) - v(k - 1)) / (s - key_fraction(i - 1));
    const float after = (v(k + 1) - v(k)) / (key_fraction(i + 1) - s);
    return before * after > 0.0f ? 2.0f * before * after / (before + after) : 0.0f;
}

// How far the swing travels across, for its path: the ankle's horizontal
// distance, or, when the foot mostly turns (a closing step, a step in place),
// the horizontal chord its toe tip sweeps turning from its lift-off to its
// landing rotation, if that is longer. The path's arc length then gives the
// turn its share of the swing's time: measured by the ankle alone, a foot that
// lifts, turns 20° over a few millimetres and sets down would turn in one tick.
float swing_travel(const FootState& f, const GaitRig& rig) {
    const float distance = horizontal_distance(f.start, f.target);
    const vec3 tip = sole_offsets(rig)[2];
    const float sweep = horizontal_distance(quat_rotate(f.start_rotation, tip), quat_rotate(f.target_rotation, tip));
    return maxf(distance, sweep);
}

// The swing path's Hermite keys from its heights: key i at s = key_fraction(i),
// position (0, height, key_reach(i) · travel); both coordinates have monotone
// tangents, so the foot never moves back or overshoots a key's height.
// `distance` is swing_travel(f, rig), which the callers have at hand.
void swing_path_keys(const FootState& f, float distance, std::array<HermiteKey, kSwingPathKeys>& keys) {
    constexpr int n = kSwingPathKeys;
    const auto height = [&](std::size_t k) { return f.path_height[k]; };
    const auto along = [&](std::size_t k) { return key_reach(static_cast<int>(k)) * distance; };
    for (int i = 0; i < n; ++i) {
        const std::size_t k = static_cast<std::size_t>(i);
        keys[k] = {key_fraction(i), vec3(0.0f, height(k), along(k)), vec3(0.0f, monotone_tangent(height, i), monotone_tangent(along, i))};
    }
}

constexpr float kNoGroundM = 1e9f;     // m: below any ground
constexpr float kSweepSampleM = 0.01f;  // m between ground samples along a sole point's way from key to key

// The highest ground (less a toes-down foot's drop, as at the keys) that the
// sole points pass over between two neighbouring keys, each point moving
// straight from where it is at one key (ankle a0, rotation q0) to where it is
// at the next: a box corner or a riser edge between two keys' samples is seen.
float ground_between_keys(const GroundWindow& terrain, const GaitRig& rig, vec3 a0, quat q0, vec3 a1, quat q1) {
    float h = -kNoGroundM;
    for (const vec3& o : sole_offsets(rig)) {
        const vec3 p0 = quat_rotate(q0, o), p1 = quat_rotate(q1, o);
        const float drop = maxf(-p0.y, -p1.y) - rig.ankle_height;
        h = maxf(h, max_height_along(terrain, a0.x + p0.x, a0.z + p0.z, a1.x + p1.x, a1.z + p1.z, kSweepSampleM) + drop);
    }
    return h;
}

// The most the walk or the run prototype swings a foot sideways (m, at lift scale 1).
constexpr int kSideSamples = 24;
float max_swing_side(const GaitRig& rig) {
    float side = 0.0f;
    for (int j = 0; j <= kSideSamples; ++j) {
        const float u = static_cast<float>(j) / static_cast<float>(kSideSamples);
        side = maxf(side, maxf(std::fabs(eval_keys(rig.walk.swing_foot, rig.walk.swing_count, u).x),
                               std::fabs(eval_keys(rig.run.swing_foot, rig.run.swing_count, u).x)));
    }
    return side;
}

constexpr float kRiserM = 0.01f;             // m: ground this much above the foot's spot next to it is a riser
constexpr float kLiftOffClearanceM = 0.005f;  // m: the straight lift-off and set-down away from risers
constexpr float kMaxPathGrade = 1.0f;          // rise (or fall) per metre of travel toward (or from) a high key, at most

// The swing path (docs/gait.md): the ankle's height at evenly spaced fractions
// s of the step's horizontal distance, as a monotone cubic Hermite spline in the
// vertical plane of the step, (height, horizontal distance) against s.
//
// Each interior key is the higher of the prototype's shape there (the line from
// lift-off to landing plus the blended lift) and the clearance floor: the highest
// ground under the sole (ankle, ball, toe tip, for the toe directions of the
// start, the target and halfway) at that key and both neighbours, plus the
// ankle height and swing_clearance. Monotone tangents keep the curve between two
// keys within their heights, so the sole clears every sampled ground between
// them: the path rises before a step up and comes down only past a step edge.
bool build_swing_path(FootState& f, const Terrain& whole_terrain, const GaitRig& rig, const GaitConfig& c, float blend) {
    constexpr int n = kSwingPathKeys;
    // Every ground query below lies within the sole's reach (or the sideways
    // swing) of the straight line from start to target: the boxes there are
    // gathered once (a query elsewhere would still scan them all: same results).
    // The foot swings out sideways by the prototype's x (along the root's left
    // as it is then, which a turn changes): the ground under the ankle counts
    // within that distance along both axes of the ground.
    const float side = max_swing_side(rig) * f.lift_scale;
    const float margin = side + rig.foot_length + rig.toe_length + rig.ankle_height + 0.05f;
    const GroundWindow terrain = ground_window(whole_terrain, minf(f.start.x, f.target.x) - margin, minf(f.start.z, f.target.z) - margin,
                                               maxf(f.start.x, f.target.x) + margin, maxf(f.start.z, f.target.z) + margin);
    // The foot at a key turns between its rotations at the neighbouring keys.
    std::array<quat, n> rotation{};
    for (int i = 0; i < n; ++i) rotation[static_cast<std::size_t>(i)] = swing_rotation(f, key_reach(i));
    const std::array<vec3, 3> sole = sole_offsets(rig);
    std::array<float, n> ground{};
    for (int i = 0; i < n; ++i) {
        const vec3 a = lerp(f.start, f.target, key_reach(i));
        float h = query_ground(terrain, a.x, a.z).height;
        if (side > 0.0f)
            for (const vec2& d : {vec2(side, 0.0f), vec2(-side, 0.0f), vec2(0.0f, side), vec2(0.0f, -side)})
                h = maxf(h, query_ground(terrain, a.x + d.x, a.z + d.y).height);
        const quat turns[3] = {rotation[static_cast<std::size_t>(i > 0 ? i - 1 : 0)], rotation[static_cast<std::size_t>(i)],
                               rotation[static_cast<std::size_t>(i + 1 < n ? i + 1 : n - 1)]};
        for (const quat& q : turns) {
            const vec3 forward = quat_rotate(q, vec3(0.0f, 0.0f, 1.0f));
            for (float r : {rig.foot_length, rig.foot_length + rig.toe_length})
                h = maxf(h, query_ground(terrain, a.x + forward.x * r, a.z + forward.z * r).height);
            // The toe tip swung out sideways too: a foot lifting beside a riser
            // its toes point at, 1 cm from its edge, swung them into it (sweep
            // case 13-0408, 145 mm).
            const vec3 tip = a + forward * (rig.foot_length + rig.toe_length);
            if (side > 0.0f)
                for (const vec2& d : {vec2(side, 0.0f), vec2(-side, 0.0f), vec2(0.0f, side), vec2(0.0f, -side)})
                    h = maxf(h, query_ground(terrain, tip.x + d.x, tip.z + d.y).height);
            // A foot pitched toes-down (landing on a ramp below it) carries its
            // ball and toe tip below the sole under the ankle: the ankle must
            // clear the ground under them by that much more.
            for (const vec3& o : sole) {
                const vec3 p = quat_rotate(q, o);
                h = maxf(h, query_ground(terrain, a.x + p.x, a.z + p.z).height - p.y - rig.ankle_height);
            }
        }
        ground[static_cast<std::size_t>(i)] = h;
    }
    for (int i = 0; i + 1 < n; ++i) {
        const std::size_t k = static_cast<std::size_t>(i);
        const float between = ground_between_keys(terrain, rig, lerp(f.start, f.target, key_reach(i)), rotation[k],
                                                  lerp(f.start, f.target, key_reach(i + 1)), rotation[k + 1]);
        ground[k] = maxf(ground[k], between);
        ground[k + 1] = maxf(ground[k + 1], between);
    }
    // The prototype's lift against the fraction of the step it has covered:
    // (fraction, lift) sampled evenly in swing progress, fraction rising.
    constexpr int m = 24;
    std::array<float, m + 1> shape_fraction{}, shape_lift{};
    for (int j = 0; j <= m; ++j) {
        const vec3 shape = blended_swing(rig, blend, static_cast<float>(j) / static_cast<float>(m));
        shape_fraction[static_cast<std::size_t>(j)] = clampf(shape.z, 0.0f, 1.0f);
        shape_lift[static_cast<std::size_t>(j)] = shape.y;
    }
    int j = 0;
    f.path_height[0] = f.start.y;
    f.path_height[static_cast<std::size_t>(n - 1)] = f.target.y;
    for (int i = 1; i + 1 < n; ++i) {
        const float s = key_reach(i);
        while (j + 1 < m && shape_fraction[static_cast<std::size_t>(j + 1)] < s) ++j;
        const float f0 = shape_fraction[static_cast<std::size_t>(j)], f1 = shape_fraction[static_cast<std::size_t>(j + 1)];
        const float w = f1 > f0 ? clampf((s - f0) / (f1 - f0), 0.0f, 1.0f) : 1.0f;
        const float lift = shape_lift[static_cast<std::size_t>(j)] + (shape_lift[static_cast<std::size_t>(j + 1)] - shape_lift[static_cast<std::size_t>(j)]) * w;
        const float shaped = f.start.y + (f.target.y - f.start.y) * s + lift * f.lift_scale;
        const std::size_t k = static_cast<std::size_t>(i);
        float floor = maxf(ground[k], maxf(ground[k - 1], ground[k + 1])) + rig.ankle_height + c.swing_clearance;
        // The straight lift-off and set-down (keys 1 and n − 2, over the foot's
        // own spot) need the full clearance only below a riser next to the
        // spot; else they rise kLiftOffClearanceM, so a step on level ground
        // does not start with a jerk straight up.
        if ((i == 1 || i == n - 2) && f.lift_scale >= 1.0f) {
            const std::size_t next = i == 1 ? k + 1 : k - 1;
            if (!(ground[next] > ground[k] + kRiserM)) floor = ground[k] + rig.ankle_height + kLiftOffClearanceM;
        }
        f.path_height[k] = maxf(shaped, floor);
    }
    // The path climbs toward a high key no steeper than kMaxPathGrade and falls
    // from one no steeper either: an edge's clearance is met by a ramp, not by a
    // plateau and a wall (that kink snapped the knee at speed, up a flight).
    const float travel = swing_travel(f, rig);
    for (int i = 1; i + 1 < n; ++i) {
        const std::size_t k = static_cast<std::size_t>(i);
        for (int jj = 1; jj + 1 < n; ++jj) {
            const float d = std::fabs(key_reach(i) - key_reach(jj)) * travel;
            f.path_height[k] = maxf(f.path_height[k], f.path_height[static_cast<std::size_t>(jj)] - kMaxPathGrade * d);
        }
    }
    f.path_travel = travel;
    swing_path_keys(f, travel, f.path_keys);
    f.path_length = build_arc_length_table(f.path_keys);
    // Whether the path climbs a wall: ground under it more than max_step_height
    // above both ends of the step (begin_swing then tries another turn order).
    const float wall = maxf(f.start_ground, f.target_ground) + c.max_step_height;
    for (int i = 1; i + 1 < n; ++i)
        if (ground[static_cast<std::size_t>(i)] > wall) return true;
    return false;
}

// How much of the mid-swing reach allowance (kFullLegReachShare over the
// planted reach) a swing at progress u has: 4u(1 − u), 0 at lift-off and
// landing; a re-aimed swing starts with what its predecessor had (carry) and
// lets it go over its progress, so re-aiming never takes the allowance away in
// one tick (that dropped the pelvis by centimetres in a tick and snapped both
// knees).
float swing_reach_bump(float progress, float carry) {
    const float u = clampf(progress, 0.0f, 1.0f);
    return maxf(4.0f * u * (1.0f - u), carry * (1.0f - u));
}

// Whether a planted foot there would stand on top of an obstacle (a wall's top,
// not a stair tread) or within kWallFootClearanceM of one's face: around its
// ankle and toe tip, ground more than max_step_height above its sole, or ground
// that is the top of a box whose faces rise more than max_step_height.
bool on_obstacle(const Terrain& terrain, const GaitRig& rig, const Placement& p, float max_step_height) {
    const vec3 tip = p.ankle + quat_rotate(p.rotation, vec3(0.0f, -rig.ankle_height, rig.foot_length + rig.toe_length));
    for (const vec3& q : {p.ankle, tip})
        for (const vec2& d : {vec2(0.0f, 0.0f), vec2(kWallFootClearanceM, 0.0f), vec2(-kWallFootClearanceM, 0.0f),
                              vec2(0.0f, kWallFootClearanceM), vec2(0.0f, -kWallFootClearanceM)}) {
            const float x = q.x + d.x, z = q.z + d.y;
            const float h = query_ground(terrain, x, z).height;
            // Ground more than a step above the sole within the clearance: a
            // wall's face (the swing path would climb it); on a wall's top: the
            // top itself.
            if (h > p.ground + max_step_height) return true;
            if (obstacle_depth(terrain, vec3(x, h - kObstacleTopProbeM, z), max_step_height) > 0.0f) return true;
        }
    return false;
}

// A foot's spot kept off obstacles: a spot on one moves toward `toward` (a spot
// known to be on the walkable side: beside the planted foot, under the root) to
// the first spot that fits and is off every obstacle. Stop and turning steps
// are placed beside a foot or the root, and a foot planted near a wall while
// approaching it put its neighbour's stop step on the wall's top (sweep case
// 3-0001, a 2.16 m wall).
Placement keep_off_obstacles(const Terrain& terrain, const GaitRig& rig, const Placement& placed, vec3 spot, vec3 toward,
                             vec3 forward, float max_step_height) {
    if (!on_obstacle(terrain, rig, placed, max_step_height)) return placed;
    for (int k = 1; k <= kObstacleSearchSteps; ++k) {
        const vec3 at = lerp(spot, toward, static_cast<float>(k) / static_cast<float>(kObstacleSearchSteps));
        const Placement candidate = place_foot_on_flat_spot(terrain, rig, at.x, at.z, forward);
        if (!on_obstacle(terrain, rig, candidate, max_step_height)) return candidate;
    }
    return place_foot_on_flat_spot(terrain, rig, toward.x, toward.z, forward);
}

// A step kept within `max_rise` of the planted foot's ground: a spot rising or
// dropping more moves back toward `beside` (the spot beside the planted foot)
// to the farthest spot that fits, is off obstacles and is within it (the
// nearest in rise if none is). A stride that took three or four stair risers
// at once (walking at 0.8 m/s after a turn on 22 cm stairs, running down a
// flight) folded the higher leg to 0.11 m hip–ankle and whipped its thigh and
// foot past 2,000 °/s; one or two risers a step is what a person takes.
Placement keep_within_rise(const Terrain& terrain, const GaitRig& rig, const Placement& placed, vec3 spot, vec3 beside,
                           vec3 forward, float planted_ground, float max_rise, float max_step_height) {
    if (std::fabs(placed.ground - planted_ground) <= max_rise) return placed;
    Placement nearest = placed;
    for (int k = 1; k <= kRiseSearchSteps; ++k) {
        const vec3 at = lerp(spot, beside, static_cast<float>(k) / static_cast<float>(kRiseSearchSteps));
        const Placement candidate = place_foot(terrain, rig, at.x, at.z, forward);
        if (candidate.misfit >= kFitTolerance || on_obstacle(terrain, rig, candidate, max_step_height)) continue;
        const float rise = std::fabs(candidate.ground - planted_ground);
        if (rise < std::fabs(nearest.ground - planted_ground)) nearest = candidate;
        if (rise <= max_rise) break;
    }
    return nearest;
}

void find_turn_window(FootState& f, const GaitRig& rig, float blend);

// Starts (or re-aims) a swing from where the foot is now toward a planted target.
void begin_swing(FootState& f, const Placement& target, const Terrain& terrain, const GaitRig& rig, const GaitConfig& c,
                 float blend, float lift_phase, float timed_rate) {
    f.reach_carry = f.swinging ? swing_reach_bump(f.progress, f.reach_carry) : 0.0f;
    f.start = f.ankle;
    f.start_rotation = f.rotation;
    f.start_ground = f.ground;
    f.target = target.ankle;
    f.target_rotation = target.rotation;
    f.target_ground = target.ground;
    f.progress = 0.0f;
    f.fraction = 0.0f;
    f.lift_phase = lift_phase;
    f.timed_rate = timed_rate;
    const float distance = horizontal_distance(f.start, f.target);
    f.lift_scale = clampf(distance / 0.3f, 0.35f, 1.0f);
    f.swinging = 1;
    f.reaim_velocity = vec3(0.0f);
    f.reaim_spin = vec3(0.0f);
    f.reaim_time = 0.0f;
    f.reaim_span = 0.0f;
    // A foot turning beside a wall can sweep its toes through the wall's corner
    // while both its spots are clear, and its path would climb the wall (sweep
    // case 2-0085: toes 3.5 cm from a 1.09 m wall, turning 52° away from it
    // while stepping 0.11 m toward it). A short step (under 0.3 m: a stop
    // shuffle, a turn in place) then turns the foot over the first half of the
    // step, or else the second, if that path is clear of the wall. A longer
    // stride keeps its path over the wall: its clearance keys lie too far
    // apart for a turn packed into half the step (sweep case 7-0196: a toe
    // tip swept 449 mm below a 0.53 m wall's top).
    f.turn_order = 0;
    if (build_swing_path(f, terrain, rig, c, blend) && f.lift_scale < 1.0f) {
        const FootState turning = f;
        bool cleared = false;
        for (std::int32_t order : {-1, 1}) {
            f.turn_order = order;
            if (!build_swing_path(f, terrain, rig, c, blend)) {
                cleared = true;
                break;
            }
        }
        if (!cleared) f = turning;
    }
    find_turn_window(f, rig, blend);
}

// Where the swing puts the foot at progress u. The blended prototype's z says
// what share of the path's length (arc length, climbing and descending
// included) the foot has covered by then: the arc-length table turns that into
// the step fraction s, so a foot stepping down a riser slows its horizontal
// progress while it descends instead of dropping in a few ticks.
struct SwingPoint {
    vec3 ankle;
    float reach;  // share of the step's horizontal distance covered
};
SwingPoint swing_point(const FootState& f, int foot, const GaitRig& rig, float blend, vec3 left, float progress) {
    const float u = clampf(progress, 0.0f, 1.0f);
    const vec3 shape = blended_swing(rig, blend, u);  // (sideways, lift, share of the path)
    const float share = clampf(shape.z, 0.0f, 1.0f);
    const float distance = f.path_travel;  // the keys and travel of the swing, built at its start
    const std::span<const HermiteKey> path(f.path_keys.data(), f.path_keys.size());
    const float total = f.path_length.total();
    const float s = total > 1e-6f ? clampf(time_at_arc_length(path, f.path_length, share * total), 0.0f, 1.0f) : share;
    const vec3 on_path = sample_hermite_position(path, s);  // (0, height, travel along the step)
    const float reach = distance > 1e-6f ? clampf(on_path.z / distance, 0.0f, 1.0f) : s;
    // The sideways swing fades out over the straight lift-off and set-down, so
    // the foot leaves and reaches its spots straight up and down.
    const float out = clampf(minf(reach, 1.0f - reach) / kHoldRotationShare, 0.0f, 1.0f);
    vec3 p = lerp(f.start, f.target, reach) + left * (side_sign(foot) * shape.x * f.lift_scale * out);
    p.y = on_path.y;
    return {p, reach};
}

// The swing's progress where its step fraction passes `reach` (interior:
// between the straight lift-off and set-down). The fraction is linear in the
// path's parameter s there (swing_path_keys: key_reach against key_fraction),
// the arc-length table gives the share of the path's length covered at s, and
// the prototype's z says at what progress that share is reached: inverted by
// bisection, kTurnWindowSteps halvings (it never falls as progress rises).
// Bisecting swing_point itself, the same window cost 4 % more instructions a
// walk tick (the arc-length inversion per evaluation).
constexpr int kTurnWindowSteps = 12;
float progress_at_reach(const FootState& f, const GaitRig& rig, float blend, float reach) {
    constexpr int n = kSwingPathKeys;
    const float grid = static_cast<float>(kKeyGrid[1]) + reach * static_cast<float>(kKeyGrid[n - 2] - kKeyGrid[1]);
    const int j = static_cast<int>(grid) < kArcLengthIntervals - 1 ? static_cast<int>(grid) : kArcLengthIntervals - 1;
    const float w = grid - static_cast<float>(j);
    const std::array<float, kArcLengthIntervals + 1>& length = f.path_length.length;
    const float covered = length[static_cast<std::size_t>(j)] + (length[static_cast<std::size_t>(j + 1)] - length[static_cast<std::size_t>(j)]) * w;
    const float total = f.path_length.total();
    const float share = total > 1e-6f ? covered / total : grid / static_cast<float>(kArcLengthIntervals);
    float lo = 0.0f, hi = 1.0f;
    for (int k = 0; k < kTurnWindowSteps; ++k) {
        const float mid = 0.5f * (lo + hi);
        if (clampf(blended_swing(rig, blend, mid).z, 0.0f, 1.0f) < share) lo = mid;
        else hi = mid;
    }
    return hi;
}

// The posed turn's window (posed_swing_rotation), once per swing: the path
// and its arc-length table are built; the blend may drift a little over the
// swing, which moves the fraction's 0.1 and 0.9 by as little.
void find_turn_window(FootState& f, const GaitRig& rig, float blend) {
    const TurnShares t = turn_shares(f);
    f.turn_from = progress_at_reach(f, rig, blend, t.from);
    f.turn_to = maxf(f.turn_from, progress_at_reach(f, rig, blend, t.to));
}

// The carried re-aim velocity's displacement after t of span T: v·t·(1 − t/T)²,
// which starts at the velocity v and ends at rest, back on the new path, at T.
vec3 reaim_offset(const FootState& f) {
    if (f.reaim_span <= 0.0f || f.reaim_time >= f.reaim_span) return vec3(0.0f);
    const float rest = 1.0f - f.reaim_time / f.reaim_span;
    return f.reaim_velocity * (f.reaim_time * rest * rest);
}

constexpr float kReaimCarryS = 0.1f;              // s: a re-aim's carried velocity dies out over at most this
constexpr float kReaimCarryShare = 0.5f;          // … and at most this share of the new swing's time
constexpr float kMaxReaimCarrySpeed = 6.0f;       // m/s: the most velocity a re-aim carries
constexpr float kMaxReaimCarrySpin = 10.0f;       // rad/s: the most turn rate it carries

// The carried spin's turn after t of span T: |w|·t·(1 − t/T)² about w.
quat reaim_turn(const FootState& f) {
    if (f.reaim_span <= 0.0f || f.reaim_time >= f.reaim_span) return quat_identity();
    const float rate = std::sqrt(dot3(f.reaim_spin, f.reaim_spin));
    if (rate <= 1e-6f) return quat_identity();
    const float rest = 1.0f - f.reaim_time / f.reaim_span;
    return quat_axis_angle(f.reaim_spin / rate, static_cast<double>(rate * (f.reaim_time * rest * rest)));
}

// The same for the foot's turn: the new swing holds its start rotation for a
// while (kHoldRotationShare), so a foot turning toward the old target stopped
// turning in one tick and the foot joint spun (gait14). Its rate from `from`
// (last tick) to `old_now` is carried, at most kMaxReaimCarrySpin.
void carry_swing_spin(FootState& f, quat old_now, quat from, float dt) {
    f.reaim_spin = vec3(0.0f);
    quat d = quat_mul(old_now, quat_conjugate(from));
    if (d.w < 0.0f) d = quat(-d.w, -d.x, -d.y, -d.z);
    const float s = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    if (s <= 1e-7f) return;
    const float angle = static_cast<float>(2.0 * det::atan2(s, d.w));
    const float rate = minf(angle / dt, kMaxReaimCarrySpin);
    f.reaim_spin = vec3(d.x, d.y, d.z) * (rate / s);
}

// A swing just restarted toward a new target (begin_swing: from rest) takes
// over the velocity the old one moved the foot at, from `from` (last tick) to
// `old_now` (where the old swing puts it this tick): sideways, forward and up,
// never down, dying out over at most kReaimCarryS and kReaimCarryShare of the
// new swing's `swing_time`; `elapsed` of it has passed by the swing's next
// evaluation. (Tried for a stop's quick swing too: 79 → 80 failing of the
// 6,000 sweep cases, one sole into the ground; not kept.)
void carry_swing_velocity(FootState& f, vec3 old_now, vec3 from, float dt, float swing_time, float elapsed) {
    vec3 v = (old_now - from) / dt;
    if (v.y < 0.0f) v.y = 0.0f;
    const float speed = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    if (speed > kMaxReaimCarrySpeed) v *= kMaxReaimCarrySpeed / speed;
    f.reaim_velocity = v;
    f.reaim_time = elapsed;
    f.reaim_span = minf(kReaimCarryS, kReaimCarryShare * swing_time);
}

void evaluate_swing(FootState& f, int foot, const GaitConfig& c, const GaitRig& rig, float blend, vec3 left) {
    (void)c;
    const SwingPoint at = swing_point(f, foot, rig, blend, left, f.progress);
    f.fraction = at.reach;
    f.ankle = at.ankle + reaim_offset(f);
    f.rotation = posed_swing_rotation(f, f.progress);
    if (f.reaim_span > 0.0f && dot3(f.reaim_spin, f.reaim_spin) > 0.0f)
        f.rotation = quat_normalize(quat_mul(reaim_turn(f), f.rotation));
    f.ground = f.start_ground + (f.target_ground - f.start_ground) * at.reach;
}

void land(FootState& f, GaitState& g) {
    f.ankle = f.target;
    f.rotation = f.target_rotation;
    f.ground = f.target_ground;
    f.swinging = 0;
    f.progress = 0.0f;
    f.timed_rate = 0.0f;
    f.replanned = 0;
    f.reaim_velocity = vec3(0.0f);
    f.reaim_spin = vec3(0.0f);
    f.reaim_time = 0.0f;
    f.reaim_span = 0.0f;
    f.turn_from = 0.0f;
    f.turn_to = 1.0f;
    ++g.steps;
}

struct StepPlan {
    float duration;  // one step, s
    float duty;
};

// The cadence follows the speed a quarter second ahead, so that while the
// puppet speeds up its steps quicken before the root outruns the planted foot.
StepPlan step_plan(const GaitConfig& c, float speed, float commanded, bool turning_in_place) {
    if (turning_in_place) return {0.5f * (c.min_step_duration + c.max_step_duration), c.walk_duty};
    const float ahead = maxf(speed, minf(commanded, speed + 0.25f * c.acceleration));
    return {step_duration(c, ahead), duty_for(c, ahead)};
}

// What the phases after steering read: the fixed inputs and what steering decided.
struct GaitTick {
    const GaitConfig& c;
    const GaitRig& rig;
    const Terrain& terrain;
    float dt;
    float heading;          // after this tick's turn
    float desired_heading;  // where the root is aimed: the stick's direction, or along a face it slides on
    HeadingFrame h;         // of `heading`
    StepPlan plan;          // this tick's step duration and duty
    float dphase;           // how far the cycle phase moves this tick
    SteerGoal goal;         // the stick's ask (speed 0: released), for the path prediction
    float target_speed;     // what the speed moved toward this tick
    const NearbyWalls& walls;
};

// What the steering law and the step clock will do if the stick holds: where
// the root is, and how it faces, when a swing lands and half the foot's coming
// stance later (under the hip then is where the foot should be planted).
struct PathPrediction {
    float time = 0.0f;     // s until the swing foot lands
    RootMotion landing;    // the root then
    RootMotion mid_stance; // … and half its coming stance later
    double turned = 0.0;   // rad the heading turns until then, unwrapped (+ left)
};

constexpr int kMaxPredictedTicks = 1200;
constexpr float kMaxTurnPerStepDeg = 90.0f;  // most a foot turns in one swing
constexpr float kMaxFootTurnDegS = 300.0f;   // … and on average per second of the swing
// Radians a foot may turn in a swing landing in `seconds`.
double max_foot_turn(float seconds) { return minf(kMaxTurnPerStepDeg, kMaxFootTurnDegS * seconds) * det::kDegToRad; }
// Seconds a timed swing (a stop, a closing step) takes at least, so that its
// foot turns from `from` to `to` at no more than kMaxFootTurnDegS on average:
// held to stop_transition_s, a foot turned 100–175° in 0.15–0.3 s and the foot
// joint passed 1500 °/s (sweep cases 1-0071, 1-0136, 7-0012, 7-0289 ...).
float turn_time(quat from, quat to) {
    return static_cast<float>(quat_angle_between(from, to) * det::kRadToDeg) / kMaxFootTurnDegS;
}

// Runs the tick's own steering law (steer_root: turns, braking, walls) and step
// clock forward tick by tick from this tick's root until the foot's phase
// completes, then half the stance that follows, so the landing time and the
// root's place and heading then are what will really happen if the stick holds.
PathPrediction predict_path(const GaitState& g, const GaitTick& t, vec3 root, float remaining_phase) {
    PathPrediction out;
    RootMotion m{root.x, root.z, t.heading, g.speed, g.turning_in_place};
    float phase_left = remaining_phase;
    float target = t.target_speed;
    int k = 0;
    for (; k < kMaxPredictedTicks && phase_left > 0.0f; ++k) {
        const float before = m.heading;
        if (t.goal.speed > 0.0f) target = steer_root(m, t.goal, t.walls, t.c, t.dt).target_speed;
        out.turned += det::wrap_angle(static_cast<double>(m.heading) - before);
        phase_left -= t.dt / (2.0f * step_plan(t.c, m.speed, target, m.turning_in_place != 0).duration);
        out.time += t.dt;
    }
    out.landing = m;
    const StepPlan next = step_plan(t.c, m.speed, target, m.turning_in_place != 0);
    float stance_left = next.duty * next.duration;  // half of duty · 2 · duration
    for (; k < kMaxPredictedTicks && stance_left > 0.0f; ++k) {
        const float before = m.heading;
        if (t.goal.speed > 0.0f) steer_root(m, t.goal, t.walls, t.c, t.dt);
        out.turned += det::wrap_angle(static_cast<double>(m.heading) - before);
        stance_left -= t.dt;
    }
    out.mid_stance = m;
    return out;
}

// Where a swing starting now should land: under its hip at the middle of its
// coming stance on the predicted path (the first step from standstill half as
// far ahead of the root at landing), facing the heading then, on a flat spot of
// the terrain. On a straight path at constant speed this is ahead of the root
// at landing by half the distance it covers during the stance.
Placement plan_target(const GaitState& g, const GaitTick& t, int foot, vec3 root, float remaining_phase) {
    const PathPrediction p = predict_path(g, t, root, remaining_phase);
    const HeadingFrame then = heading_frame(p.mid_stance.heading);
    vec3 under(p.mid_stance.x, 0.0f, p.mid_stance.z);
    if (g.first_step) under = 0.5f * (under + vec3(p.landing.x, 0.0f, p.landing.z));
    const vec3 spot = under + then.left * (side_sign(foot) * t.rig.hip_half_width);
    // The foot turns at most kMaxTurnPerStepDeg in one swing, and no faster than
    // kMaxFootTurnDegS on average (a sharp turn takes more steps to face round).
    // It turns the way the root will (gait19): toward the heading now, then on
    // by the turn predicted, unwrapped. Aimed at the heading then by the
    // shortest way, a foot behind a root spinning with a circling stick (the
    // heading then more than 180° round from the toes) turned against the spin,
    // and the next re-aim turned it back: sweep case 7-0163, the foot joint at
    // 1,697 °/s.
    const vec3 toes = quat_rotate(g.feet[static_cast<std::size_t>(foot)].rotation, vec3(0.0f, 0.0f, 1.0f));
    const double yaw = det::atan2(toes.x, toes.z);
    const double turn_wanted = det::wrap_angle(static_cast<double>(t.heading) - yaw) + p.turned;
    const double facing = yaw + clamp_magnitude(turn_wanted, max_foot_turn(p.time));
    const vec3 forward = heading_frame(facing).forward;
    const vec3 hip_now = root + t.h.left * (side_sign(foot) * t.rig.hip_half_width);
    const Placement placed = keep_off_obstacles(t.terrain, t.rig, place_foot_on_flat_spot(t.terrain, t.rig, spot.x, spot.z, forward),
                                                spot, hip_now, forward, t.c.max_step_height);
    const FootState& other = g.feet[static_cast<std::size_t>(1 - foot)];
    // In a run's flight the other foot is not planted yet: its landing is what
    // this step rises or drops from. Unlimited there, one foot re-aimed four
    // risers above the other while the other re-aimed down, and the higher leg
    // folded past its hip (sweep case 10-0487, 2,206 °/s; gait13).
    const vec3 other_at = other.swinging ? other.target : other.ankle;
    const float other_ground = other.swinging ? other.target_ground : other.ground;
    const vec3 beside = other_at + then.left * (side_sign(foot) * 2.0f * t.rig.hip_half_width);
    return keep_within_rise(t.terrain, t.rig, placed, spot, beside, forward, other_ground,
                            kMaxStrideRiseShare * (t.rig.thigh + t.rig.shin), t.c.max_step_height);
}

// s: a late lift-off still swings this long. 0.12 s until gait20: a turn in
// place re-aiming a swing late in its phase took a foot 0.31 m across and
// 0.39 m down a hillside in 0.12 s and the shin spun (sweep case 14-0014,
// foot joint 1,577 °/s).
constexpr float kShortestSwing = 0.14f;
constexpr float kWristDrag = 0.4f;                // hand tilt against its path's velocity, per m/cycle
constexpr float kMaxPelvisVerticalSpeed = 0.9f;   // m/s the pelvis follows its height target at, at most
// m/s the pelvis sinks at, at most, to meet a landing swing's soft limit: the
// limit moves with where the hip will be at touchdown, and a run's other foot
// lifting moved that 4 cm in one tick, 0.95 of the way through the swing; the
// pelvis fell 5 cm in that tick and both shins spun (2,685 °/s, sweep case
// 5-0439). Whatever is left at touchdown, the planted reach takes over.
constexpr float kMaxPelvisSinkSpeed = 3.0f;
constexpr float kSwingFoldShare = 0.3f;           // of the leg: how far a swinging ankle stays below its hip
constexpr float kSwingFoldRiseSpeed = 1.5f;       // m/s the pelvis may rise at to keep it there
constexpr float kMaxStopSwingHipTurn = 12.0f;     // rad/s (~690 °/s) a stop swing's hip–ankle line may turn at
constexpr float kMinStopSwingShare = 0.25f;       // of its timed progress a stop swing takes a tick, at least

// Standing spot for a foot beside the other (planted) foot.
Placement stop_target(const GaitState& g, int foot, float heading, const GaitRig& rig, const Terrain& terrain,
                      float max_step_height) {
    const HeadingFrame h = heading_frame(heading);
    const vec3 other = g.feet[static_cast<std::size_t>(1 - foot)].ankle;
    const vec3 spot = other + h.left * (side_sign(foot) * 2.0f * rig.hip_half_width);
    return keep_off_obstacles(terrain, rig, place_foot_on_flat_spot(terrain, rig, spot.x, spot.z, h.forward), spot, other,
                              h.forward, max_step_height);
}

}  // namespace

int sample_swing_path(const FootState& foot, int side, const GaitRig& rig, float run_blend, float heading,
                      std::span<vec3> out) {
    if (!foot.swinging || out.size() < 2) return 0;
    const vec3 left = heading_frame(heading).left;
    const std::size_t n = out.size();
    for (std::size_t i = 0; i < n; ++i) {
        const float u = static_cast<float>(i) / static_cast<float>(n - 1);
        out[i] = swing_point(foot, side, rig, run_blend, left, u).ankle;
    }
    return static_cast<int>(n);
}

float stick_speed_fraction(float deflection, const GaitConfig& c) {
    if (deflection <= c.stick_deadzone) return 0.0f;
    float d = (deflection - c.stick_deadzone) / (1.0f - c.stick_deadzone);
    d = clampf(d, 0.0f, 1.0f);
    return (1.0f - c.response_curve) * d + c.response_curve * d * d;
}

namespace {
// The ground's grade along the heading is measured over a stride-sized window
// (kGradeBehindM behind to kGradeAheadM ahead of the point), so a flight of
// stairs reads as its pitch (rise over tread), not as flat treads and
// vertical risers, and the puppet slows as it reaches a flight.
constexpr float kGradeBehindM = 0.4f;
constexpr float kGradeAheadM = 0.8f;
// m/s: the most the puppet climbs or descends while walking (docs/gait.md):
// on steep ground the horizontal speed is capped at this over the grade.
constexpr float kMaxClimbSpeed = 0.6f;
}  // namespace

namespace {
// ground_grade_along for a heading whose frame is at hand (update_gait has it).
float grade_along(const Terrain& terrain, float x, float z, const HeadingFrame& h) {
    const float ahead = query_ground(terrain, x + h.forward.x * kGradeAheadM, z + h.forward.z * kGradeAheadM).height;
    const float behind = query_ground(terrain, x - h.forward.x * kGradeBehindM, z - h.forward.z * kGradeBehindM).height;
    return (ahead - behind) / (kGradeAheadM + kGradeBehindM);
}
}  // namespace

float ground_grade_along(const Terrain& terrain, float x, float z, float heading) {
    return grade_along(terrain, x, z, heading_frame(heading));
}

namespace {
// The slope factor of a measured grade (both public functions below use it).
float slope_multiplier_of_grade(const GaitConfig& c, float grade) {
    if (grade == 0.0f) return 1.0f;  // level: what the formula gives, without the atan
    const double degrees = det::atan(std::fabs(static_cast<double>(grade))) * det::kRadToDeg;
    return clampf(1.0f - c.slope_speed_factor * static_cast<float>(degrees), 0.2f, 1.0f);
}
}  // namespace

float slope_speed_multiplier(const Terrain& terrain, const GaitConfig& c, float x, float z, float heading) {
    return slope_multiplier_of_grade(c, ground_grade_along(terrain, x, z, heading));
}

namespace {
// The commanded speed on a measured grade (ground_speed, and update_gait with
// the heading frame it already has).
float speed_on_grade(const GaitConfig& c, float stick_fraction, float signed_grade) {
    const float grade = std::fabs(signed_grade);
    const float wanted = c.max_speed * stick_fraction * slope_multiplier_of_grade(c, signed_grade);
    return grade * wanted > kMaxClimbSpeed ? kMaxClimbSpeed / grade : wanted;
}
}  // namespace

// The grade is measured once (four ground queries and a heading frame): it used
// to be measured again inside slope_speed_multiplier, with the same result.
float ground_speed(const Terrain& terrain, const GaitConfig& c, float stick_fraction, float x, float z, float heading) {
    return speed_on_grade(c, stick_fraction, ground_grade_along(terrain, x, z, heading));
}

GaitRig make_gait_rig(const GaitConfig& c) {
    GaitRig rig;
    rig.walk.swing_count = build_prototype_keys(c.walk.swing_foot, false, rig.walk.swing_foot);
    rig.walk.pelvis_count = build_prototype_keys(c.walk.pelvis, true, rig.walk.pelvis);
    rig.walk.hand_count = build_prototype_keys(c.walk.hand, true, rig.walk.hand);
    rig.run.swing_count = build_prototype_keys(c.run.swing_foot, false, rig.run.swing_foot);
    rig.run.pelvis_count = build_prototype_keys(c.run.pelvis, true, rig.run.pelvis);
    rig.run.hand_count = build_prototype_keys(c.run.hand, true, rig.run.hand);
    rig.thigh = c.thigh_length;
    rig.shin = c.shin_length;
    rig.ankle_height = c.ankle_height;
    rig.foot_length = c.foot_length;
    rig.toe_length = c.toe_length;
    rig.hip_half_width = 0.5f * c.hip_width;
    rig.upper_arm = c.upper_arm_length;
    rig.forearm = c.forearm_length;
    // Inside the IK's exact zone (soft reach starts at 0.98), with a margin.
    rig.leg_reach = 0.96f * (c.thigh_length + c.shin_length);
    return rig;
}

GaitState initial_gait_state(const GaitConfig& c, const GaitRig& rig, const Terrain& terrain, vec3 root, float heading) {
    GaitState g;
    const HeadingFrame h = heading_frame(heading);
    float ground_sum = 0.0f;
    for (int i = 0; i < 2; ++i) {
        const vec3 spot = root + h.left * (side_sign(i) * rig.hip_half_width);
        const Placement p = place_foot(terrain, rig, spot.x, spot.z, h.forward);
        FootState& f = g.feet[static_cast<std::size_t>(i)];
        f.ankle = p.ankle;
        f.rotation = p.rotation;
        f.ground = p.ground;
        ground_sum += p.ground;
    }
    g.pelvis_base = 0.5f * ground_sum;
    g.pelvis = vec3(root.x, g.pelvis_base + c.gait_pelvis_height, root.z);
    return g;
}

namespace {

// update_gait's constants (docs/gait.md). The doubles enter double arithmetic
// (angles), the floats float arithmetic, exactly as the literals did.
constexpr double kStepTurnRad = 0.2;               // a wider turn is stepped even at zero speed; its side picks the lead foot
constexpr float kForceReaim = -1.0f;               // a planned_speed no command has: the swing re-aims at its next check
constexpr float kStepsPerCycle = 2.0f;             // a gait cycle is one left and one right step
constexpr float kRightFootPhase = 0.5f;            // the right foot's cycle phase lags the left's by half a cycle
constexpr float kMinStopSwingLeftS = 0.02f;        // s: a swing cut short by a stop keeps at least this much
constexpr float kMaxStopFootSpeed = 3.0f;          // m/s: a foot re-aimed by a stop moves no faster
constexpr float kMinStopSwingS = 0.15f;            // s: a foot re-aimed by a stop swings at least this long
constexpr float kRunBlendSpan = 0.6f;              // m/s of speed over which the walk → run blend goes from 0 to 1
constexpr float kRunBlendAtThreshold = 0.5f;       // the walk/run blend at exactly run_threshold
constexpr float kMinSwingPhaseShare = 1e-3f;       // least (1 − lift phase) a swing's pace divides by
constexpr float kReaimSpeedChange = 0.25f;         // m/s: a commanded speed change this large re-aims a swing
constexpr double kReaimHeadingChangeRad = 0.25;    // rad: a stick direction change this large re-aims a swing
constexpr float kLatestReaimProgress = 0.6f;       // a swing further along keeps its target
constexpr float kStanceReachM = 0.42f;             // m: the root keeps each planted foot this close to its hip, horizontally
constexpr std::int32_t kMaxReaims = 3;             // a swing re-aims at most this often (the stick turning on)
constexpr float kMinReaimShiftM = 0.06f;           // m: a new target closer than this to the old one is not taken
constexpr float kStrandedLandingM = 0.5f;          // m: a landing spot this far from its hip at landing re-aims at any progress
constexpr float kStopStaggerM = 0.05f;             // m: feet further apart along the heading close up when stopping
constexpr float kMinClosingStepS = 0.25f;          // s: the closing step takes at least this long
constexpr float kClosingStepStretch = 1.5f;        // … and otherwise this many times stop_transition_s
constexpr float kFullActivitySpeed = 1.0f;         // m/s at which bob and arm swing reach full amplitude
constexpr float kPelvisBaseRateScale = 1.5f;       // the pelvis base follows the ground this much faster than interpolation_rate
constexpr float kFullLegReachShare = 0.995f;       // mid-swing the hip may be this share of thigh + shin from the ankle
constexpr float kFarSwingM = 0.6f;                 // m: a swinging ankle this far from its hip (horizontally) is left behind …
constexpr float kStanceFloorShare = 0.35f;         // … and its reach lowers the pelvis to this share of the leg above a planted ankle, no lower
constexpr float kMinHipDropShareSq = 0.09f;        // the hip stays at least 0.3 of the reach (squared: 0.09) above the ankle
constexpr float kEarlyLiftPhase = 0.05f;          // … at most this much of a cycle before its duty factor
constexpr float kEarlyLiftReachShare = 0.9f;      // a planted foot this share of the leg reach behind its hip lifts
constexpr float kEarlyLiftStanceShare = 0.95f;    // … or this share of kStanceReachM (before the root pivots on it)
constexpr float kSinkByProgress = 0.95f;           // a swing's soft limit is met by this progress, just before touchdown
constexpr float kNoLimitM = 1e9f;                  // m: a pelvis height limit that no foot imposes

// The stick's command this tick.
struct StickCommand {
    float fraction = 0.0f;         // of max_speed, after deadzone and response curve
    bool moving = false;           // outside the deadzone
    float desired_heading = 0.0f;  // radians; the current heading when not moving
    float dir_x = 0.0f, dir_z = 1.0f;  // the stick's direction in XZ (unit), when moving
};

// Stick → commanded speed fraction and direction (stick up walks toward −Z).
StickCommand read_stick(const GaitTickInput& in, const GaitConfig& c, float heading) {
    StickCommand cmd;
    const float length = std::sqrt(in.stick_x * in.stick_x + in.stick_y * in.stick_y);
    cmd.fraction = stick_speed_fraction(minf(1.0f, length), c);
    cmd.moving = cmd.fraction > 0.0f;
    cmd.desired_heading = heading;
    if (cmd.moving) {
        cmd.desired_heading = static_cast<float>(det::atan2(in.stick_x, -in.stick_y));
        cmd.dir_x = in.stick_x / length;
        cmd.dir_z = -in.stick_y / length;
    }
    return cmd;
}

// The planted feet's horizontal distances from their hips (−1: swinging).
struct StanceReach {
    float distance[2] = {-1.0f, -1.0f};
};
StanceReach stance_reach(const GaitState& g, vec3 root, const HeadingFrame& h, const GaitRig& rig) {
    StanceReach r;
    for (int i = 0; i < 2; ++i) {
        const FootState& f = g.feet[static_cast<std::size_t>(i)];
        if (!f.swinging) r.distance[i] = horizontal_distance(root + h.left * (side_sign(i) * rig.hip_half_width), f.ankle);
    }
    return r;
}

// The root pivots on the planted feet: it never takes a hip further than
// kStanceReachM (or, if it already was, than it was before this tick) from its
// planted foot, so a stick that turned after a foot was planted swings the body
// round that foot instead of dragging the leg out of reach.
void keep_stance_in_reach(const GaitState& g, vec3& root, const HeadingFrame& h, const GaitRig& rig, const StanceReach& before) {
    for (int pass = 0; pass < 2; ++pass)
        for (int i = 0; i < 2; ++i) {
            const FootState& f = g.feet[static_cast<std::size_t>(i)];
            if (f.swinging || before.distance[i] < 0.0f) continue;
            const vec3 hip = root + h.left * (side_sign(i) * rig.hip_half_width);
            const float dx = hip.x - f.ankle.x, dz = hip.z - f.ankle.z;
            const float d = std::sqrt(dx * dx + dz * dz);
            const float limit = maxf(kStanceReachM, before.distance[i]);
            if (d <= limit) continue;
            const float back = 1.0f - limit / d;
            root.x -= dx * back;
            root.z -= dz * back;
        }
}

// What steering decided this tick.
struct Steering {
    SteerGoal goal;
    SteerResult result;
};

// The root moves by the steering law (steer_root, runtime/gait/steering.hpp):
// the stick's velocity clipped against obstacles, the heading turned no faster
// than the lateral acceleration allows, the speed braked for sharp turns and
// wide reversals turned in place once braked. A released stick stops at once.
// Swings aimed for one way of moving re-aim when turning in place starts or ends.
Steering steer(GaitState& g, float& heading, HeadingFrame& frame, vec3& root, const StickCommand& cmd, const NearbyWalls& walls,
               const GaitConfig& c, const Terrain& terrain, float dt) {
    Steering s;
    s.result.heading = heading;
    if (!cmd.moving) {
        g.commanded_speed = 0.0f;
        g.speed = 0.0f;  // stopping is immediate in movement
        g.turning_in_place = 0;
        return s;
    }
    g.commanded_speed = speed_on_grade(c, cmd.fraction, grade_along(terrain, root.x, root.z, frame));
    s.goal = {cmd.dir_x, cmd.dir_z, cmd.desired_heading, g.commanded_speed};
    RootMotion m{root.x, root.z, heading, g.speed, g.turning_in_place};
    s.result = steer_root(m, s.goal, walls, c, dt);
    if (m.turning_in_place != g.turning_in_place)
        for (FootState& f : g.feet) {
            f.replanned = 0;
            f.planned_speed = kForceReaim;
        }
    g.turning_in_place = m.turning_in_place;
    g.speed = m.speed;
    heading = m.heading;
    root.x = m.x;
    root.z = m.z;
    // steer_root's last sine and cosine are of the heading now: its frame, the
    // bits heading_frame gives (float(−s) is −float(s)).
    if (m.facing_known && std::memcmp(&m.facing_heading, &m.heading, sizeof m.heading) == 0)
        frame = {vec3(m.facing_x, 0.0f, m.facing_z), vec3(m.facing_z, 0.0f, -m.facing_x)};
    else frame = heading_frame(heading);
    return s;
}

// Idle or stopping → stepping. From idle the first step (half length) leads with
// the foot on the side of the turn, else the left.
void start_stepping(GaitState& g, const GaitTick& t, double diff) {
    if (g.mode == GaitMode::idle) {
        const int lead = diff < -kStepTurnRad ? 1 : 0;
        g.cycle_phase = frac((lead == 0 ? 0.0f : kRightFootPhase) + t.plan.duty);
        g.first_step = 1;
    }
    g.mode = GaitMode::stepping;
    // A foot still on its quick stop swing finishes it at its own pace (a
    // phase-driven pace from lift phase 0 would take a whole cycle while the
    // root walks on); it lands where it was going and steps on from there,
    // unless the root leaves that spot behind (reaim_if_command_changed).
    for (FootState& f : g.feet)
        if (!f.swinging) f.timed_rate = 0.0f;
}

// Stepping → stopping: a foot in the air re-aims beside the planted one and lands quickly.
void start_stopping(GaitState& g, const GaitTick& t, vec3 root) {
    g.mode = GaitMode::stopping;
    for (int i = 0; i < 2; ++i) {
        FootState& f = g.feet[static_cast<std::size_t>(i)];
        const FootState& other = g.feet[static_cast<std::size_t>(1 - i)];
        if (!f.swinging) continue;
        const float remaining =
            maxf(kMinStopSwingLeftS, (1.0f - f.progress) * (1.0f - f.lift_phase) * kStepsPerCycle * t.plan.duration);
        // In a flight phase neither foot is down to stand beside: both go under their hips.
        const vec3 spot = root + t.h.left * (side_sign(i) * t.rig.hip_half_width);
        const Placement p = other.swinging ? place_foot_on_flat_spot(t.terrain, t.rig, spot.x, spot.z, t.h.forward)
                                           : stop_target(g, i, t.heading, t.rig, t.terrain, t.c.max_step_height);
        // Short (at most stop_transition_s), but never faster than
        // kMaxStopFootSpeed for the foot, its drop or rise included, nor turning
        // faster than kMaxFootTurnDegS on average. (The speed cap was clamped to
        // stop_transition_s before: a foot re-aimed 0.9 m across and 0.45 m down
        // a stair flight to a stop swung there in 0.29 s, 3.5 m/s, and its ankle
        // turned at 1,757 °/s: sweep case 7-0283.)
        const float time = maxf(maxf(clampf(remaining, kMinStopSwingS, t.c.stop_transition_s),
                                     length3(p.ankle - f.ankle) / kMaxStopFootSpeed),
                                turn_time(f.rotation, p.rotation));
        begin_swing(f, p, t.terrain, t.rig, t.c, g.run_blend, 0.0f, 1.0f / time);
    }
}

void change_mode(GaitState& g, const GaitTick& t, vec3 root, bool wants_steps, double diff) {
    if (wants_steps && g.mode != GaitMode::stepping) start_stepping(g, t, diff);
    else if (!wants_steps && g.mode == GaitMode::stepping) start_stopping(g, t, root);
}

// Where foot i, lifting (or re-aiming) with `remaining` of the cycle's phase
// until it lands, should land.
Placement aim_swing(const GaitState& g, const GaitTick& t, vec3 root, int i, float remaining) {
    if (!g.turning_in_place)
        return plan_target(g, t, i, root, remaining);
    // Turning in place: small steps to the hip's spot under the turned heading.
    const float time_to_land = predict_path(g, t, root, remaining).time;
    const double turn = det::wrap_angle(static_cast<double>(t.desired_heading) - t.heading);
    // Small steps: a foot turns at most kMaxTurnPerStepDeg per swing.
    const double max_turn = minf(minf(t.c.turn_rate_deg_s, kMaxFootTurnDegS) * time_to_land, kMaxTurnPerStepDeg) * det::kDegToRad;
    const double heading_then = t.heading + clamp_magnitude(turn, max_turn);
    const HeadingFrame then = heading_frame(heading_then);
    const vec3 spot = root + then.left * (side_sign(i) * t.rig.hip_half_width);
    // The foot turns that far from its own facing, not from the root's: a foot
    // still facing behind the turned root would otherwise turn up to 180° in one swing.
    const vec3 toes = quat_rotate(g.feet[static_cast<std::size_t>(i)].rotation, vec3(0.0f, 0.0f, 1.0f));
    const double yaw = det::atan2(toes.x, toes.z);
    const double facing = yaw + clamp_magnitude(det::wrap_angle(heading_then - yaw), max_turn);
    const vec3 forward = heading_frame(facing).forward;
    return keep_off_obstacles(t.terrain, t.rig, place_foot_on_flat_spot(t.terrain, t.rig, spot.x, spot.z, forward), spot, root,
                              forward, t.c.max_step_height);
}

// The shortest a phase-driven swing may take: kShortestSwing, and its travel
// at kMaxMeanSwingSpeed. A foot lifting (or re-aimed) late in its phase had the
// cycle's few remaining hundredths of a second for up to 0.9 m: its shin passed
// 1500 °/s (wall × reversals after a long stop swing, 1506 °/s).
float shortest_swing_for(float travel) { return maxf(kShortestSwing, travel / kMaxMeanSwingSpeed); }
// A built swing also takes its whole path, climbs and drops included, at no
// more than kMaxMeanSwingPathSpeed (gait17): held to its horizontal travel
// only, a step in place beside a riser (0.32 m across) lifted 0.22 m straight
// up, went across and down 0.2 m in 0.12 s, 9 m/s up, and the shin turned at
// 1,930 °/s where the path turned from up to across (sweep case 7-0961).
// f.path_travel is swing_travel(f, rig), computed once at the swing's start,
// with the path's arc-length table. (Aiming, aimed_target, still estimates the
// time from the travel alone: adding the rise or drop there, 44 → 47 failing
// of the 6,000 sweep cases.)
constexpr float kMaxMeanSwingPathSpeed = 5.0f;  // m/s along the swing path, on average
float shortest_swing(const FootState& f) {
    return maxf(shortest_swing_for(f.path_travel), f.path_length.total() / kMaxMeanSwingPathSpeed);
}

// Where foot i's phase-driven swing starting (or re-aiming) now at its phase
// psi lands: aimed for the time it will take. A swing held to its travel at
// kMaxMeanSwingSpeed outlasts the phase left when an ordinary swing already
// moves near 4 m/s (a run near 1.9 m/s): aimed for the phase's time, it landed
// behind the root, was flagged stranded and re-aimed over and over (the
// spun-stick test's case 27, foot_l 5,358 °/s). It is aimed again for its own,
// longer time then.
Placement aimed_target(const GaitState& g, const GaitTick& t, vec3 root, int i, float psi) {
    const float remaining = 1.0f - psi;
    const Placement first = aim_swing(g, t, root, i, remaining);
    if (!(t.dphase > 0.0f)) return first;
    FootState trial = g.feet[static_cast<std::size_t>(i)];
    trial.start = trial.ankle;
    trial.start_rotation = trial.rotation;
    trial.target = first.ankle;
    trial.target_rotation = first.rotation;
    const float phase_time = maxf(kMinSwingPhaseShare, remaining) * t.dt / t.dphase;
    // trial is not built (no path_travel yet): its travel from its start and target.
    const float swing_time = shortest_swing_for(swing_travel(trial, t.rig));
    return swing_time > phase_time ? aim_swing(g, t, root, i, swing_time * t.dphase / t.dt) : first;
}

// Starts (or re-aims) foot i's phase-driven swing at its phase psi toward aimed_target.
void begin_aimed_swing(GaitState& g, const GaitTick& t, int i, float psi, const Placement& target) {
    begin_swing(g.feet[static_cast<std::size_t>(i)], target, t.terrain, t.rig, t.c, g.run_blend, psi, 0.0f);
}

// The foot's phase for a re-aim. A swing that outlasts its phase (held to its
// travel at kMaxMeanSwingSpeed) sees the foot's phase wrap past 1 to near 0:
// re-aimed with that, a whole cycle was left to land in, the spot lay a cycle
// ahead, and the swing was stranded again (8 re-aims in 0.85 s, case 27). After
// the wrap it keeps its lift phase.
float swing_phase_now(const FootState& f, float cycle_phase, int i) {
    const float psi = foot_phase(cycle_phase, i);
    return psi < f.lift_phase ? f.lift_phase : psi;
}

// The swing's progress per second: at its own rate after a stop, else with the
// cycle's phase (over what was left of it at lift-off), but never slower than a
// kShortestSwing swing.
float swing_rate(const FootState& f, const GaitTick& t) {
    return f.timed_rate > 0.0f ? f.timed_rate
                               : minf(t.dphase / t.dt / maxf(kMinSwingPhaseShare, 1.0f - f.lift_phase), 1.0f / shortest_swing(f));
}

// Where a swing's hip will be when it lands, if the root keeps its speed and heading.
vec3 hip_at_landing(const FootState& f, const GaitState& g, const GaitTick& t, vec3 root, int i) {
    const float remaining = maxf(0.0f, 1.0f - f.progress) / swing_rate(f, t);
    return root + t.h.left * (side_sign(i) * t.rig.hip_half_width) + t.h.forward * (g.speed * remaining);
}

// A swing re-aims (up to kMaxReaims times, early in the swing) when the stick
// changed the landing spot a lot. A swing whose landing spot the root has left
// behind (a sharp turn or a turn in place starting late in the swing: the spot
// more than kStrandedLandingM from where its hip will be) re-aims at any
// progress, however often it already did, when that brings the spot closer:
// landing there would take the leg out of reach (the pelvis sinks to reach it,
// the planted foot is dragged).
void reaim_if_command_changed(GaitState& g, const GaitTick& t, vec3 root, int i) {
    FootState& f = g.feet[static_cast<std::size_t>(i)];
    const bool command_changed =
        std::fabs(g.commanded_speed - f.planned_speed) > kReaimSpeedChange ||
        std::fabs(det::wrap_angle(static_cast<double>(t.desired_heading) - f.planned_heading)) > kReaimHeadingChangeRad;
    const bool stepping = g.mode == GaitMode::stepping && f.timed_rate == 0.0f;
    const vec3 hip_then = hip_at_landing(f, g, t, root, i);
    const float gap = horizontal_distance(f.target, hip_then);
    // A foot still on its stop swing when stepping resumed (start_stepping: it
    // finishes at its own pace) is stranded as easily: the root runs off while
    // it hovers toward a spot beside where the other foot stood. It re-aims too,
    // phase-driven from then (gait21): left to land, one hovered 0.57 s while the
    // root sped to 3 m/s, the pelvis sank to 0.33 m to reach it and the thigh
    // spun at 2,551 °/s (sweep case 7-0755, sliding along a wall).
    const bool stranded = g.mode == GaitMode::stepping && gap > kStrandedLandingM;
    const bool may_reaim =
        (stepping && command_changed && f.replanned < kMaxReaims && f.progress < kLatestReaimProgress) || stranded;
    if (!may_reaim) return;
    const float psi = swing_phase_now(f, g.cycle_phase, i);
    // A stranded swing is judged by the spot it would really be re-aimed at
    // (aimed_target: for the time the swing will take). Judged by the phase's
    // spot while the longer time's spot was taken, a stranded swing on a
    // turning path re-aimed every tick to about the spot it had, its progress
    // held at 0 for up to 140 ticks while the pelvis sank to reach the spot
    // and the lifting foot was pulled into the tread behind it (sweep cases
    // 2-0052, 104 mm, and 7-0655, 15.7 mm, walking down and up stairs with the
    // stick circling). A command change is still judged by the phase's spot.
    const Placement aimed = stranded ? aimed_target(g, t, root, i, psi) : aim_swing(g, t, root, i, 1.0f - psi);
    const bool closer = !stranded || horizontal_distance(aimed.ankle, hip_then) < gap - kMinReaimShiftM;
    if (closer && horizontal_distance(aimed.ankle, f.target) > kMinReaimShiftM) {
        const float ground = f.ground;
        // Where the old swing puts the foot this tick: the velocity it moved at.
        const SwingPoint old_at = swing_point(f, i, t.rig, g.run_blend, t.h.left, f.progress);
        const vec3 old_now = old_at.ankle + reaim_offset(f);
        const quat old_rotation = quat_mul(reaim_turn(f), posed_swing_rotation(f, f.progress));
        const quat from_rotation = f.rotation;
        const vec3 from = f.ankle;
        begin_aimed_swing(g, t, i, psi, stranded ? aimed : aimed_target(g, t, root, i, psi));
        f.start_ground = ground;
        ++f.replanned;
        // The new path starts from rest (it lifts straight up, its progress eases
        // in), so the foot stopped dead in one tick and the shin spun (sweep cases
        // 12-0383 and 14-0468 at 1,686 and 4,254 °/s, 7-0456 at 3,800 °/s). The
        // velocity the old swing moved at is carried instead and dies out over
        // the span: sideways, forward and up, never down (carried down, it took
        // the sole into the ground; docs/gait.md, gait12).
        carry_swing_velocity(f, old_now, from, t.dt, 1.0f / swing_rate(f, t), t.dt);
        carry_swing_spin(f, old_rotation, from_rotation, t.dt);
    }
    f.planned_speed = g.commanded_speed;
    f.planned_heading = t.desired_heading;
}

// The share of a stop swing's progress step (timed_rate) it may take this tick
// so that the line from its hip to its ankle turns at no more than
// kMaxStopSwingHipTurn: a stop swing is timed, and one starting with its foot
// near its hip (stranded high on a tread beside it) swept past the hip at
// 4.3 m/s, and the shin whipped with the hip–ankle line (sweep case 7-0283:
// a foot 0.07 m below its hip, stopping 1 m across and 0.55 m down, foot
// joint 1,575 °/s). Never less than kMinStopSwingShare, so the swing lands.
// The small-angle test uses the tangent (|a × b| / a·b), no trigonometry.
// Stepping swings keep their rate: they are timed by the cycle's phase.
float hip_turn_share(const GaitState& g, const GaitTick& t, int i, float step) {
    const FootState& f = g.feet[static_cast<std::size_t>(i)];
    const vec3 hip = g.pelvis + t.h.left * (side_sign(i) * t.rig.hip_half_width);
    const vec3 now = f.ankle - hip;
    const vec3 next =
        swing_point(f, i, t.rig, g.run_blend, t.h.left, minf(1.0f, f.progress + step)).ankle + reaim_offset(f) - hip;
    const float turn_sine = length3(cross3(now, next));
    const float turn_cosine = dot3(now, next);
    const float max_turn = kMaxStopSwingHipTurn * t.dt;
    if (turn_cosine <= 0.0f) return kMinStopSwingShare;
    if (turn_sine <= max_turn * turn_cosine) return 1.0f;
    return maxf(kMinStopSwingShare, max_turn * turn_cosine / turn_sine);
}

// A swinging foot moves on: at its own rate after a stop (slower while its
// hip–ankle line would turn too fast: hip_turn_share), else with the cycle's
// phase (over what was left of it at lift-off), but never slower than a
// kShortestSwing swing. It lands at progress 1.
void advance_swing(GaitState& g, const GaitTick& t, vec3 root, int i) {
    FootState& f = g.feet[static_cast<std::size_t>(i)];
    float rate = f.timed_rate > 0.0f
                     ? f.timed_rate * t.dt
                     : minf(t.dphase / maxf(kMinSwingPhaseShare, 1.0f - f.lift_phase), t.dt / shortest_swing(f));
    if (f.timed_rate > 0.0f) rate *= hip_turn_share(g, t, i, rate);
    f.progress += rate;
    if (f.progress >= 1.0f) {
        land(f, g);
        g.first_step = 0;
        return;
    }
    if (f.reaim_span > 0.0f) {
        f.reaim_time += t.dt;
        if (f.reaim_time >= f.reaim_span) {
            f.reaim_velocity = vec3(0.0f);
            f.reaim_spin = vec3(0.0f);
            f.reaim_time = 0.0f;
            f.reaim_span = 0.0f;
        }
    }
    reaim_if_command_changed(g, t, root, i);
    evaluate_swing(f, i, t.c, t.rig, g.run_blend, t.h.left);
}

// A planted foot lifts once its phase passes the duty factor; a walk never has
// both feet in the air.
void lift_if_due(GaitState& g, const GaitTick& t, vec3 root, int i) {
    FootState& f = g.feet[static_cast<std::size_t>(i)];
    const FootState& other = g.feet[static_cast<std::size_t>(1 - i)];
    const float psi = foot_phase(g.cycle_phase, i);
    const bool walking = !running(t.c, g.speed);
    // A foot left far behind its hip (a start down a slope, a long first
    // stride, the ground easing so the root speeds up past the planned stance)
    // lifts early, while the other is planted, instead of being dragged out of
    // the leg's reach or, nearer, holding the root back (keep_stance_in_reach).
    const vec3 hip = root + t.h.left * (side_sign(i) * t.rig.hip_half_width);
    const float behind = dot3(hip - f.ankle, t.h.forward);
    const bool left_behind = !other.swinging && psi >= t.plan.duty - kEarlyLiftPhase &&
                             (behind > kEarlyLiftReachShare * t.rig.leg_reach || behind > kEarlyLiftStanceShare * kStanceReachM);
    if ((psi >= t.plan.duty && (!walking || !other.swinging)) || left_behind) {
        begin_aimed_swing(g, t, i, psi, aimed_target(g, t, root, i, psi));
        f.planned_speed = g.commanded_speed;
        f.planned_heading = t.desired_heading;
        evaluate_swing(f, i, t.c, t.rig, g.run_blend, t.h.left);
    }
}

// The walk/run blend follows the speed, the cycle advances while stepping, swings
// advance and stance feet lift.
void advance_feet(GaitState& g, const GaitTick& t, vec3 root) {
    const float blend_target = clampf((g.speed - t.c.run_threshold) / kRunBlendSpan + kRunBlendAtThreshold, 0.0f, 1.0f);
    g.run_blend = approach(g.run_blend, blend_target, t.c.interpolation_rate, t.dt);
    if (g.mode == GaitMode::stepping) g.cycle_phase = frac(g.cycle_phase + t.dphase);
    for (int i = 0; i < 2; ++i) {
        if (g.feet[static_cast<std::size_t>(i)].swinging) advance_swing(g, t, root, i);
        else if (g.mode == GaitMode::stepping) lift_if_due(g, t, root, i);
    }
}

// Stopping with both feet down: the trailing foot steps beside the other in one
// step, or, when they are already side by side, the gait rests.
void finish_stopping(GaitState& g, const GaitTick& t) {
    if (g.mode != GaitMode::stopping || g.feet[0].swinging || g.feet[1].swinging) return;
    const float along = dot3(g.feet[0].ankle - g.feet[1].ankle, t.h.forward);
    if (std::fabs(along) > kStopStaggerM) {
        const int trailing = along < 0.0f ? 0 : 1;
        FootState& f = g.feet[static_cast<std::size_t>(trailing)];
        const Placement p = stop_target(g, trailing, t.heading, t.rig, t.terrain, t.c.max_step_height);
        const float time = maxf(maxf(kMinClosingStepS, t.c.stop_transition_s * kClosingStepStretch), turn_time(f.rotation, p.rotation));
        begin_swing(f, p, t.terrain, t.rig, t.c, g.run_blend, 0.0f, 1.0f / time);
        evaluate_swing(f, trailing, t.c, t.rig, g.run_blend, t.h.left);
    } else {
        g.mode = GaitMode::idle;
    }
}

void count_flight_phases(GaitState& g) {
    const bool flight = g.feet[0].swinging && g.feet[1].swinging;
    if (flight && !g.flight_phases_open) ++g.flight_phases;
    g.flight_phases_open = flight ? 1 : 0;
}

// Activity follows the speed (none when idle); an idle root settles over the
// middle of the feet; the pelvis base follows the mean ground under the feet.
void settle_root(GaitState& g, const GaitTick& t, vec3& root) {
    const float activity_target = g.mode == GaitMode::idle ? 0.0f : clampf(g.speed / kFullActivitySpeed, 0.0f, 1.0f);
    g.activity = approach(g.activity, activity_target, t.c.interpolation_rate, t.dt);
    if (g.mode == GaitMode::idle) {
        const vec3 mid = 0.5f * (g.feet[0].ankle + g.feet[1].ankle);
        root.x = approach(root.x, mid.x, t.c.interpolation_rate, t.dt);
        root.z = approach(root.z, mid.z, t.c.interpolation_rate, t.dt);
    }
    const float ground_mean = 0.5f * (g.feet[0].ground + g.feet[1].ground);
    g.pelvis_base = approach(g.pelvis_base, ground_mean, t.c.interpolation_rate * kPelvisBaseRateScale, t.dt);
    root.y = g.pelvis_base;
}

// Whether an idle root still moves toward the middle of its feet (settle_root).
bool root_settling(const GaitState& g, vec3 root) {
    if (g.mode != GaitMode::idle) return false;
    const vec3 mid = 0.5f * (g.feet[0].ankle + g.feet[1].ankle);
    return std::fabs(mid.x - root.x) > kSettledM || std::fabs(mid.z - root.z) > kSettledM;
}

// The pelvis before the reach limits: over the root, at the pelvis base plus
// the configured height, with the prototype's bob and sway, breathing when still.
vec3 unlimited_pelvis(const GaitState& g, const GaitTick& t, vec3 root, float breath_time) {
    const float step_phase = frac(kStepsPerCycle * g.cycle_phase);
    const vec3 bob = blended_pelvis(t.rig, g.run_blend, step_phase) * g.activity;
    const float stance_side = g.cycle_phase < kRightFootPhase ? 1.0f : -1.0f;  // left foot leads the first half
    const double breath = det::sin(det::kTwoPi * breath_time / t.c.breath_period_s);
    vec3 pelvis = root + t.h.left * (bob.x * stance_side) + t.h.forward * bob.z;
    pelvis.y = g.pelvis_base + t.c.gait_pelvis_height + bob.y +
               static_cast<float>(breath) * t.c.breath_amplitude * (1.0f - g.activity);
    return pelvis;
}

// Where a swing's hip will be at landing, as hip_at_landing, but walking (the
// other foot stays planted until this one lands) the root pivots on that
// planted foot (keep_stance_in_reach): it goes no further along the heading than
// keeps the other hip within kStanceReachM of its foot (or as far as it is now).
// Predicted without that, the pelvis met the soft limit late when the root
// stalled on the planted foot and then dropped onto the hard limit.
vec3 hip_at_landing_in_reach(const FootState& f, const GaitState& g, const GaitTick& t, vec3 pelvis, int i) {
    const vec3 hip_then = hip_at_landing(f, g, t, pelvis, i);
    const int j = 1 - i;
    const FootState& other = g.feet[static_cast<std::size_t>(j)];
    if (other.swinging || running(t.c, g.speed)) return hip_then;
    const vec3 hip = pelvis + t.h.left * (side_sign(i) * t.rig.hip_half_width);
    const vec3 other_hip = pelvis + t.h.left * (side_sign(j) * t.rig.hip_half_width);
    const float px = other_hip.x - other.ankle.x, pz = other_hip.z - other.ankle.z;
    const float b = px * t.h.forward.x + pz * t.h.forward.z;
    const float p2 = px * px + pz * pz;
    const float r = maxf(kStanceReachM, std::sqrt(p2));
    const float most = -b + std::sqrt(maxf(0.0f, b * b - (p2 - r * r)));
    const float ahead = (hip_then.x - hip.x) * t.h.forward.x + (hip_then.z - hip.z) * t.h.forward.z;
    if (ahead <= most) return hip_then;
    const float back = ahead - maxf(0.0f, most);
    return hip_then - t.h.forward * back;
}

// How far below the hip an ankle at squared horizontal distance horizontal2 is,
// for a squared hip–ankle reach2 (at least 0.3 of the reach).
float hip_drop(float horizontal2, float reach2) { return std::sqrt(maxf(reach2 - horizontal2, kMinHipDropShareSq * reach2)); }

struct PelvisLimits {
    float hard = kNoLimitM;        // m: keeps every planted ankle (and every swinging one near its hip) within its reach now
    float far_swing = kNoLimitM;   // m: keeps the swinging ankles far from their hips within reach now
    float soft = kNoLimitM;        // m: keeps each swing's landing within the planted reach
    float descent = 0.0f;          // m/s: how fast the pelvis must sink to meet the soft limit by the swing's landing
    float floor = -kNoLimitM;      // m: the lowest far_swing may take it (kStanceFloorShare over a planted ankle)
};

// Planted feet bind exactly (within the IK's exact zone). A swinging foot binds
// where it will land, seen from where its hip will be then (the soft limit, which
// the pelvis approaches at a bounded vertical speed, so stepping down lowers it
// over the swing instead of in the last few ticks); the swing foot itself only
// has to stay within the full leg (the IK's soft reach).
PelvisLimits pelvis_limits(const GaitState& g, const GaitTick& t, vec3 pelvis) {
    const GaitRig& rig = t.rig;
    const float reach2 = rig.leg_reach * rig.leg_reach;
    const float full_reach = kFullLegReachShare * (rig.thigh + rig.shin);
    PelvisLimits limit;
    for (int i = 0; i < 2; ++i) {
        const FootState& f = g.feet[static_cast<std::size_t>(i)];
        const vec3 hip = pelvis + t.h.left * (side_sign(i) * rig.hip_half_width);
        const float dx = f.ankle.x - hip.x, dz = f.ankle.z - hip.z;
        if (!f.swinging) {
            limit.hard = minf(limit.hard, f.ankle.y + hip_drop(dx * dx + dz * dz, reach2));
            limit.floor = maxf(limit.floor, f.ankle.y + kStanceFloorShare * (rig.thigh + rig.shin));
            continue;
        }
        // The planted reach at lift-off and landing, the full leg mid-swing, so
        // neither lifting nor landing changes the limit in one tick.
        const float swing_reach = rig.leg_reach + (full_reach - rig.leg_reach) * swing_reach_bump(f.progress, f.reach_carry);
        const float swing_limit = f.ankle.y + hip_drop(dx * dx + dz * dz, swing_reach * swing_reach);
        if (dx * dx + dz * dz > kFarSwingM * kFarSwingM) limit.far_swing = minf(limit.far_swing, swing_limit);
        else limit.hard = minf(limit.hard, swing_limit);
        const vec3 hip_then = hip_at_landing_in_reach(f, g, t, pelvis, i);
        const float tx = f.target.x - hip_then.x, tz = f.target.z - hip_then.z;
        const float soft = f.target.y + hip_drop(tx * tx + tz * tz, reach2);
        limit.soft = minf(limit.soft, soft);
        const float remaining = maxf(t.dt, maxf(0.0f, kSinkByProgress - f.progress) / swing_rate(f, t));
        limit.descent = maxf(limit.descent, (g.pelvis.y - soft) / remaining);
    }
    return limit;
}

// How fast the pelvis must rise now (m/s, at most kSwingFoldRiseSpeed; 0 when
// it need not rise) to be kSwingFoldShare of the leg above each swing path's
// highest point still ahead by the time the ankle gets there. The path's keys
// are its clearance levels; the set-down (the last kHoldRotationShare of the
// step) is left out: there the landing's own limits hold the pelvis, and a
// rise demanded in the last ticks of an uphill landing fought the soft limit
// (5-0498, a shin at 1,550 °/s).
float swing_peak_rise(const GaitState& g, const GaitTick& t, float pelvis_y) {
    float rate = 0.0f;
    for (const FootState& f : g.feet) {
        if (!f.swinging || f.path_travel <= 1e-6f) continue;
        // Keys by their travel along the step (no division per key).
        const float from = f.fraction * f.path_travel;
        const float to = (1.0f - kHoldRotationShare) * f.path_travel;
        float peak = -kNoLimitM, peak_travel = 0.0f;
        for (const HermiteKey& key : f.path_keys)
            if (key.position.z > from && key.position.z < to && key.position.y > peak) {
                peak = key.position.y;
                peak_travel = key.position.z;
            }
        const float peak_floor = peak + kSwingFoldShare * (t.rig.thigh + t.rig.shin);
        if (peak_floor <= pelvis_y) continue;
        const float peak_progress =
            progress_at_reach(f, t.rig, g.run_blend, clampf(peak_travel / f.path_travel, 0.0f, 1.0f));
        if (peak_progress <= f.progress) continue;
        const float time_left = maxf(t.dt, (peak_progress - f.progress) / swing_rate(f, t));
        rate = maxf(rate, minf(kSwingFoldRiseSpeed, (peak_floor - pelvis_y) / time_left));
    }
    return rate;
}

// The pelvis: its unlimited place, lowered to the soft limit at no more than
// kMaxPelvisVerticalSpeed, or faster (up to kMaxPelvisSinkSpeed) where a swing
// needs it to meet the soft limit by kSinkByProgress of its swing (evenly over
// the time left: held to
// 0.9 m/s, the pelvis arrived late and the hard limit dropped it by up to 3 cm
// a tick just before touchdown, spinning the shin: hillside × circle
// 2865 °/s), and never above the hard limit.
void place_pelvis(GaitState& g, const GaitTick& t, vec3 root, float breath_time) {
    vec3 pelvis = unlimited_pelvis(g, t, root, breath_time);
    const PelvisLimits limit = pelvis_limits(g, t, pelvis);
    const float previous_y = g.pelvis.y;
    const float max_move = kMaxPelvisVerticalSpeed * t.dt;
    const float max_sink = maxf(kMaxPelvisVerticalSpeed, minf(kMaxPelvisSinkSpeed, limit.descent)) * t.dt;
    pelvis.y = minf(pelvis.y, limit.soft);
    pelvis.y = clampf(pelvis.y, previous_y - max_sink, previous_y + max_move);
    // A swinging ankle stays kSwingFoldShare of the leg below its hip: a swing
    // climbing two risers (0.46 m) while a planted foot far below still held
    // the pelvis down passed 7 cm from its hip and the thigh flipped (3,314 °/s,
    // sweep case 3-0256). The pelvis rises for it at up to kSwingFoldRiseSpeed,
    // under the far-swing and planted limits below, which keep their reach.
    float swing_floor = -kNoLimitM;
    for (const FootState& f : g.feet)
        if (f.swinging) swing_floor = maxf(swing_floor, f.ankle.y + kSwingFoldShare * (t.rig.thigh + t.rig.shin));
    pelvis.y = maxf(pelvis.y, minf(swing_floor, previous_y + kSwingFoldRiseSpeed * t.dt));
    // ... and rises ahead of the swing path's highest point: from where the
    // ankle will be there, not only from where it is now. Following the ankle
    // alone, the pelvis of a walk climbing two 22 cm risers in one step rose
    // at kSwingFoldRiseSpeed only once the ankle was near its peak, too late:
    // the ankle passed 0.18 m from its hip at 4.5 m/s and whipped the shin and
    // foot (1,564 °/s, sweep case 7-0154).
    const float peak_rise = swing_peak_rise(g, t, previous_y);
    if (peak_rise > 0.0f) pelvis.y = maxf(pelvis.y, previous_y + peak_rise * t.dt);
    // A swinging foot left far behind (a swing stranded at its lift-off spot
    // a metre back and below while the root runs on across a hillside) pulled
    // the pelvis down to the planted ankle, and that leg's thigh flipped at
    // 8,600 °/s (10-0441, 13-0316): its reach lowers the pelvis no further than
    // kStanceFloorShare of the leg above a planted ankle, and no faster than the
    // pelvis may sink (in a run's flight no ankle is planted: a swing re-aimed
    // behind the hip dropped it 0.2 m in 8 ticks and the other thigh flipped,
    // 3,593 °/s, sweep case 6-0372); its own leg stretches.
    const float far_swing_floor = maxf(limit.floor, previous_y - max_sink);
    pelvis.y = maxf(minf(pelvis.y, limit.far_swing), minf(pelvis.y, far_swing_floor));
    pelvis.y = minf(pelvis.y, limit.hard);
    g.pelvis = pelvis;
}

// The spine leans into the speed, up to max_spine_lean_deg.
void lean_with_speed(GaitState& g, const GaitConfig& c, float dt) {
    const float lean_target = minf(c.max_spine_lean_deg, c.spine_lean_deg_per_m_s * g.speed) * static_cast<float>(det::kDegToRad);
    g.lean = approach(g.lean, lean_target, c.interpolation_rate, dt);
}

}  // namespace

// One tick in phases: the stick steers the heading and speed and moves the root;
// the mode follows whether steps are wanted; feet swing, land and lift; a stop
// closes the stance; the root settles and the pelvis follows the feet.
void update_gait(GaitState& g, vec3& root, float& heading, vec2& velocity, const GaitTickInput& in, const GaitConfig& c,
                 const GaitRig& rig, const Terrain& terrain) {
    const float dt = in.dt;
    const StickCommand cmd = read_stick(in, c, heading);
    // Walls matter while the root moves: steered, or settling between the feet.
    const bool root_may_move = cmd.moving || g.mode != GaitMode::idle || root_settling(g, root);
    const NearbyWalls walls = root_may_move ? find_nearby_walls(terrain, c, root) : NearbyWalls{};
    const float from_x = root.x, from_z = root.z;
    // The heading's frame, before steering and (steer updates it) after.
    HeadingFrame h = heading_frame(heading);
    const StanceReach reach = stance_reach(g, root, h, rig);
    const Steering s = steer(g, heading, h, root, cmd, walls, c, terrain, dt);
    keep_stance_in_reach(g, root, h, rig, reach);
    velocity = vec2(h.forward.x * g.speed, h.forward.z * g.speed);
    const double abs_diff = s.result.diff < 0 ? -s.result.diff : s.result.diff;
    const bool wants_steps = cmd.moving && (g.speed > 0.0f || g.turning_in_place || abs_diff > kStepTurnRad);
    const StepPlan plan = step_plan(c, g.speed, s.result.target_speed, g.turning_in_place != 0);
    const GaitTick t{c,    rig,  terrain, dt, heading, s.result.heading, h, plan, dt / (kStepsPerCycle * plan.duration),
                     s.goal, s.result.target_speed, walls};
    change_mode(g, t, root, wants_steps, s.result.diff);
    advance_feet(g, t, root);
    finish_stopping(g, t);
    count_flight_phases(g);
    settle_root(g, t, root);
    keep_root_out_of_walls(walls, from_x, from_z, root.x, root.z);
    place_pelvis(g, t, root, in.breath_time);
    lean_with_speed(g, c, dt);
}

namespace {
bool finite3(vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool positive_length(float metres) { return metres > 0.0f && std::isfinite(metres); }

// The knee's pole: the hip→ankle direction turned 90° forward about the hips'
// left-right axis, so the knee points forward for a leg hanging down, up for a
// foot raised ahead to hip height, down for a foot kicked back. A fixed forward
// pole gives the same knee for a foot below the hip (the IK keeps only the
// pole's part perpendicular to the leg) but degenerates as the ankle nears hip
// height ahead of it and flips the knee through 180° when the ankle passes
// above: a swing foot over a riser or an uphill curb spun the shin at
// thousands of degrees per second. The forward part (half the leg's length)
// keeps the pole defined for a leg pointing sideways, and never changes the
// knee of a leg in the sagittal plane: shorter than the leg, it leaves the
// pole's part perpendicular to the leg a positive multiple of the turned leg.
vec3 knee_pole(const HeadingFrame& h, vec3 hip, vec3 ankle) {
    const vec3 leg = ankle - hip;
    const float ahead = dot3(leg, h.forward);
    const float up = leg.y;
    const float bias = 0.5f * length3(leg) + 1e-3f;
    return h.forward * (bias - up) + vec3(0.0f, ahead, 0.0f);
}
}  // namespace

bool GaitPoseJob::validate() const {
    const std::size_t n = static_cast<std::size_t>(kPuppetJointCount);
    if (!gait || !rig || !config || parents.size() != n || rest_offsets.size() != n || !pose.has_joints(n) ||
        !fk::order_valid(parents, fk_schedule))
        return false;
    const GaitRig& r = *rig;
    return positive_length(r.thigh) && positive_length(r.shin) && positive_length(r.upper_arm) &&
           positive_length(r.forearm) && std::isfinite(r.hip_half_width) && std::isfinite(heading) && finite3(gait->pelvis) &&
           finite3(gait->feet[0].ankle) && finite3(gait->feet[1].ankle);
}

bool GaitPoseJob::run() const {
    if (!validate()) return false;
    const GaitState& g = *gait;
    const GaitRig& r = *rig;
    const GaitConfig& c = *config;
    for (std::size_t j = 0; j < pose.local_rotations.size(); ++j) {
        pose.local_rotations[j] = quat_identity();
        pose.local_translations[j] = rest_offsets[j];
    }
    const HeadingFrame h = heading_frame(heading);
    const quat yaw = quat_axis_angle(vec3(0.0f, 1.0f, 0.0f), heading);
    pose.local_rotations[kPelvis] = yaw;
    pose.local_translations[kPelvis] = g.pelvis;
    // Spine leans into the motion (spread over three joints), breathes when still;
    // neck and head take back half the lean so the gaze stays level.
    const double breath = det::sin(det::kTwoPi * breath_time / c.breath_period_s) * (1.0f - g.activity);
    const quat spine = quat_axis_angle(vec3(1.0f, 0.0f, 0.0f), g.lean / 3.0f - 0.01 * breath);
    pose.local_rotations[kSpine1] = spine;
    pose.local_rotations[kSpine2] = spine;
    pose.local_rotations[kSpine3] = spine;
    const quat head = quat_axis_angle(vec3(1.0f, 0.0f, 0.0f), -0.25 * g.lean + 0.01 * breath);
    pose.local_rotations[kNeck] = head;
    pose.local_rotations[kHead] = head;

    // The shoulders first: their model transforms hang off the pelvis and spine
    // alone (set above), so the arms' IK needs no full forward-kinematics pass
    // before it. Computed with LocalToModelJob's arithmetic (quat_mul, then the
    // parent's position plus quat_rotate), so they are the bits the full pass
    // below writes again.
    const int clavicles[2] = {kClavicleL, kClavicleR};
    std::array<bool, kPuppetJointCount> shoulder_chain{};
    for (int clavicle : clavicles)
        for (int j = clavicle + 1; j != kNoParent; j = parents[static_cast<std::size_t>(j)]) shoulder_chain[static_cast<std::size_t>(j)] = true;
    for (std::size_t j = 0; j < shoulder_chain.size(); ++j) {
        if (!shoulder_chain[j]) continue;
        const int p = parents[j];
        if (p == kNoParent) {
            pose.model_rotations[j] = pose.local_rotations[j];
            pose.model_positions[j] = pose.local_translations[j];
        } else {
            const quat parent_rotation = pose.model_rotations[static_cast<std::size_t>(p)];
            pose.model_rotations[j] = quat_mul(parent_rotation, pose.local_rotations[j]);
            pose.model_positions[j] = pose.model_positions[static_cast<std::size_t>(p)] + quat_rotate(parent_rotation, pose.local_translations[j]);
        }
    }

    // Four two-bone IK solves in one pass (TwoBoneIkLanesJob's kernel; the
    // validation above covered its inputs): the legs from each hip to its ankle,
    // knees forward, and the arms from each shoulder to the hand path, elbows
    // back; the hands follow the blended hand paths, swinging against the legs.
    std::array<TwoBoneIkJob, 4> limbs;
    for (int i = 0; i < 2; ++i) {
        const FootState& f = g.feet[static_cast<std::size_t>(i)];
        TwoBoneIkJob& ik = limbs[static_cast<std::size_t>(i)];
        ik.root = g.pelvis + h.left * (side_sign(i) * r.hip_half_width);
        ik.target = f.ankle;
        ik.pole = knee_pole(h, ik.root, f.ankle);
        ik.upper_length = r.thigh;
        ik.lower_length = r.shin;
    }
    const float hang = 0.95f * (r.upper_arm + r.forearm);
    std::array<HermiteSample, 2> hands;
    for (int i = 0; i < 2; ++i) {
        const std::size_t clavicle = static_cast<std::size_t>(clavicles[i]);
        const vec3 shoulder = pose.model_positions[clavicle + 1];
        hands[static_cast<std::size_t>(i)] = blended_hand(r, g.run_blend, foot_phase(g.cycle_phase, i));
        const vec3 rest(0.03f, 0.0f, 0.02f);
        const vec3 offset = lerp(rest, hands[static_cast<std::size_t>(i)].position, g.activity);
        TwoBoneIkJob& ik = limbs[2 + static_cast<std::size_t>(i)];
        ik.root = shoulder;
        ik.target = shoulder + h.left * (side_sign(i) * offset.x) + vec3(0.0f, offset.y - hang, 0.0f) + h.forward * offset.z;
        ik.pole = -h.forward + h.left * (side_sign(i) * 0.3f);
        ik.upper_length = r.upper_arm;
        ik.lower_length = r.forearm;
        ik.hinge_sign = -1.0f;
    }
    std::array<TwoBoneIkResult, 4> solved;
    solve_two_bone_ik_lanes(limbs, solved);

    const int thighs[2] = {kThighL, kThighR};
    for (int i = 0; i < 2; ++i) {
        const FootState& f = g.feet[static_cast<std::size_t>(i)];
        const TwoBoneIkResult& s = solved[static_cast<std::size_t>(i)];
        const std::size_t thigh = static_cast<std::size_t>(thighs[i]);
        pose.local_rotations[thigh] = quat_normalize(quat_mul(quat_conjugate(yaw), s.upper_rotation));
        pose.local_rotations[thigh + 1] = quat_normalize(quat_mul(quat_conjugate(s.upper_rotation), s.lower_rotation));
        pose.local_rotations[thigh + 2] = quat_normalize(quat_mul(quat_conjugate(s.lower_rotation), f.rotation));
    }
    for (int i = 0; i < 2; ++i) {
        const std::size_t clavicle = static_cast<std::size_t>(clavicles[i]);
        const TwoBoneIkResult& s = solved[2 + static_cast<std::size_t>(i)];
        const quat clavicle_rotation = pose.model_rotations[clavicle];
        pose.local_rotations[clavicle + 1] = quat_normalize(quat_mul(quat_conjugate(clavicle_rotation), s.upper_rotation));
        pose.local_rotations[clavicle + 2] = quat_normalize(quat_mul(quat_conjugate(s.upper_rotation), s.lower_rotation));
        // The wrist follows the hand path's swing direction: the hand trails the
        // motion (follow-through), tilting against the path's velocity along the
        // heading and sideways, by kWristDrag per metre per cycle; at rest it
        // continues the forearm. quat_from_to: half-angle identity, no trig.
        const vec3 forearm_down = quat_rotate(s.lower_rotation, vec3(0.0f, -1.0f, 0.0f));
        const vec3 v = hands[static_cast<std::size_t>(i)].velocity * g.activity;
        const vec3 drag = h.forward * (-kWristDrag * v.z) + h.left * (-kWristDrag * side_sign(i) * v.x);
        const vec3 hand_down = normalize3(forearm_down + drag, forearm_down);
        const quat hand_rotation = quat_mul(quat_from_to(forearm_down, hand_down), s.lower_rotation);
        pose.local_rotations[clavicle + 3] = quat_normalize(quat_mul(quat_conjugate(s.lower_rotation), hand_rotation));
    }
    // validate() checked what LocalToModelJob::validate() would (span sizes,
    // parents in order or the schedule's): its kernel runs directly, once, over
    // the whole pose.
    fk::local_to_model(parents, fk_schedule, pose.local(), pose.model());
    return true;
}

}  // namespace marionette
