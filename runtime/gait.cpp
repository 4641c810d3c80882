#include "runtime/gait.hpp"

#include <cmath>

#include "runtime/puppet.hpp"
#include "runtime/skeleton.hpp"
#include "runtime/two_bone_ik.hpp"

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

vec3 eval_keys(const std::array<HermiteKey, kMaxPrototypeKeys>& keys, int count, float phase) {
    return sample_hermite(std::span<const HermiteKey>(keys.data(), static_cast<std::size_t>(count)), phase).position;
}

vec3 blended_swing(const GaitRig& rig, float blend, float u) {
    return lerp(eval_keys(rig.walk.swing_foot, rig.walk.swing_count, u), eval_keys(rig.run.swing_foot, rig.run.swing_count, u), blend);
}
vec3 blended_pelvis(const GaitRig& rig, float blend, float phase) {
    return lerp(eval_keys(rig.walk.pelvis, rig.walk.pelvis_count, phase), eval_keys(rig.run.pelvis, rig.run.pelvis_count, phase), blend);
}
vec3 blended_hand(const GaitRig& rig, float blend, float phase) {
    return lerp(eval_keys(rig.walk.hand, rig.walk.hand_count, phase), eval_keys(rig.run.hand, rig.run.hand_count, phase), blend);
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

// A planted foot at (x, z): sole on the surface, aligned to the normal there and
// to `forward`; raised just enough that no sole point is below the ground.
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
    // A riser just ahead of the toes would be kicked at lift-off: count ground
    // within 12 cm ahead rising more than 2 cm above the sole's plane as misfit.
    float misfit = lift;
    const float tip = rig.foot_length + rig.toe_length;
    for (float ahead : {tip + 0.06f, tip + 0.12f}) {
        const vec3 p = ankle + quat_rotate(rotation, vec3(0.0f, -rig.ankle_height, ahead)) + vec3(0.0f, lift, 0.0f);
        misfit = maxf(misfit, query_ground(terrain, p.x, p.z).height - p.y - 0.02f);
    }
    return {ankle + vec3(0.0f, lift, 0.0f), rotation, g.height + lift, misfit};
}

// The nearest spot along `forward` (within ±20 cm) where the whole sole rests
// on one surface, so feet never land straddling a step edge.
Placement place_foot_on_flat_spot(const Terrain& terrain, const GaitRig& rig, float x, float z, vec3 forward) {
    Placement best = place_foot(terrain, rig, x, z, forward);
    if (best.misfit < 0.004f) return best;
    static constexpr float kOffsets[] = {-0.04f, 0.04f, -0.08f, 0.08f, -0.12f, 0.12f, -0.16f, 0.16f, -0.2f, 0.2f};
    for (float d : kOffsets) {
        const Placement p = place_foot(terrain, rig, x + forward.x * d, z + forward.z * d, forward);
        if (p.misfit < 0.004f) return p;
        if (p.misfit < best.misfit) best = p;
    }
    return best;
}

float step_duration(const SimConfig& c, float speed) {
    if (speed < 0.05f) return c.max_step_duration;
    return clampf(c.step_length_multiplier / std::sqrt(speed), c.min_step_duration, c.max_step_duration);
}

bool running(const SimConfig& c, float speed) { return speed > c.run_threshold; }
float duty_for(const SimConfig& c, float speed) { return running(c, speed) ? c.run_duty : c.walk_duty; }

float foot_phase(float cycle_phase, int foot) { return frac(cycle_phase - (foot == 0 ? 0.0f : 0.5f)); }

// Highest ground under the sole along the swing, dilated by one sample so the
// foot rises before it reaches an edge.
void build_envelope(FootState& f, const Terrain& terrain, const GaitRig& rig) {
    // The toes point between the start and the target directions during the swing
    // (a turn rotates the foot): sample both, and halfway.
    const vec3 from = quat_rotate(f.start_rotation, vec3(0.0f, 0.0f, 1.0f));
    const vec3 to = quat_rotate(f.target_rotation, vec3(0.0f, 0.0f, 1.0f));
    const vec3 toes[3] = {from, to, normalize3(from + to, to)};
    std::array<float, kEnvelopeSamples> raw{};
    for (int i = 0; i < kEnvelopeSamples; ++i) {
        const float t = static_cast<float>(i) / static_cast<float>(kEnvelopeSamples - 1);
        const vec3 a = lerp(f.start, f.target, t);
        float h = query_ground(terrain, a.x, a.z).height;
        for (const vec3& forward : toes)
            for (float r : {rig.foot_length, rig.foot_length + rig.toe_length})
                h = maxf(h, query_ground(terrain, a.x + forward.x * r, a.z + forward.z * r).height);
        raw[static_cast<std::size_t>(i)] = h;
    }
    f.envelope = raw;
}

float dilated_envelope(const FootState& f, int i) {
    float h = f.envelope[static_cast<std::size_t>(i)];
    if (i > 0) h = maxf(h, f.envelope[static_cast<std::size_t>(i - 1)]);
    if (i + 1 < kEnvelopeSamples) h = maxf(h, f.envelope[static_cast<std::size_t>(i + 1)]);
    return h;
}

// The floor the swing sole keeps above at `fraction` of the step: every
// (dilated) envelope sample, falling off at a grade of kFloorGrade on either
// side, so the foot rises before an edge and comes down after it gradually.
constexpr float kFloorGrade = 0.6f;
float envelope_at(const FootState& f, float fraction, float distance) {
    float floor = -1e9f;
    const float spacing = 1.0f / static_cast<float>(kEnvelopeSamples - 1);
    for (int i = 0; i < kEnvelopeSamples; ++i) {
        const float t = static_cast<float>(i) * spacing;
        const float away = maxf(0.0f, std::fabs(fraction - t) - spacing) * distance;
        floor = maxf(floor, dilated_envelope(f, i) - kFloorGrade * away);
    }
    return floor;
}

// Starts (or re-aims) a swing from where the foot is now toward a planted target.
void begin_swing(FootState& f, const Placement& target, const Terrain& terrain, const GaitRig& rig, float lift_phase,
                 float timed_rate) {
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
    build_envelope(f, terrain, rig);
}

// Where the swing puts the foot at progress u (prototype fitted to the step).
void evaluate_swing(FootState& f, int foot, const SimConfig& c, const GaitRig& rig, float blend, vec3 left) {
    const float u = clampf(f.progress, 0.0f, 1.0f);
    const vec3 shape = blended_swing(rig, blend, u);  // (sideways, lift, fraction)
    const float fraction = clampf(shape.z, 0.0f, 1.0f);
    float y = f.start.y + (f.target.y - f.start.y) * fraction + shape.y * f.lift_scale;
    // Clearance: between its ends the sole stays swing_clearance above the
    // highest ground under it; the blend weight is 0 at both ends so the path
    // still starts and ends exactly at the planted positions.
    const float floor_y = envelope_at(f, fraction, horizontal_distance(f.start, f.target)) + rig.ankle_height + c.swing_clearance;
    const float weight = clampf(minf(u, 1.0f - u) / 0.12f, 0.0f, 1.0f);
    if (y < floor_y) y += (floor_y - y) * weight;
    f.fraction = fraction;
    vec3 p = lerp(f.start, f.target, fraction) + left * (side_sign(foot) * shape.x * f.lift_scale);
    p.y = y;
    f.ankle = p;
    const float s = u * u * (3.0f - 2.0f * u);
    f.rotation = quat_slerp(f.start_rotation, f.target_rotation, s);
    f.ground = f.start_ground + (f.target_ground - f.start_ground) * fraction;
}

void land(FootState& f, GaitState& g) {
    f.ankle = f.target;
    f.rotation = f.target_rotation;
    f.ground = f.target_ground;
    f.swinging = 0;
    f.progress = 0.0f;
    f.timed_rate = 0.0f;
    f.replanned = 0;
    ++g.steps;
}

struct StepPlan {
    float duration;  // one step, s
    float duty;
};

// The cadence follows the speed a quarter second ahead, so that while the
// puppet speeds up its steps quicken before the root outruns the planted foot.
StepPlan step_plan(const SimConfig& c, float speed, float commanded, bool turning_in_place) {
    if (turning_in_place) return {0.5f * (c.min_step_duration + c.max_step_duration), c.walk_duty};
    const float ahead = maxf(speed, minf(commanded, speed + 0.25f * c.acceleration));
    return {step_duration(c, ahead), duty_for(c, ahead)};
}

struct Landing {
    float time;        // s until the swing foot lands
    float distance;    // the root's travel until then
    float end_speed;   // the speed then
};
// Runs the speed (approaching the command at the configured acceleration) and the
// step clock (whose rate follows the speed) forward tick by tick until the foot's
// phase completes: the same arithmetic as the tick, so the landing time and the
// root's position then are what will really happen if the stick holds.
Landing predict_landing(const SimConfig& c, float speed, float commanded, float remaining_phase, bool turning, float dt) {
    Landing out{0.0f, 0.0f, speed};
    float phase_left = remaining_phase;
    const float max_dv = c.acceleration * dt;
    for (int k = 0; k < 1200 && phase_left > 0.0f; ++k) {
        if (!turning) {
            const float dv = commanded - out.end_speed;
            out.end_speed += dv > max_dv ? max_dv : (dv < -max_dv ? -max_dv : dv);
        }
        out.distance += out.end_speed * dt;
        phase_left -= dt / (2.0f * step_plan(c, out.end_speed, commanded, turning).duration);
        out.time += dt;
    }
    return out;
}

// Where a swing starting now should land: ahead of the root's predicted position
// at landing by half the distance it covers during the coming stance, beside the
// heading at the hip's lateral offset, on a flat spot of the terrain.
Placement plan_target(const GaitState& g, int foot, vec3 root, float heading, float desired_heading, const SimConfig& c,
                      const GaitRig& rig, const Terrain& terrain, float remaining_phase, float dt) {
    const Landing predicted = predict_landing(c, g.speed, g.commanded_speed, remaining_phase, false, dt);
    const float time_to_land = predicted.time;
    const double turn = det::wrap_angle(static_cast<double>(desired_heading) - heading);
    const double max_turn = c.turn_rate_deg_s * det::kDegToRad * time_to_land;
    const double landing_heading = heading + (turn > max_turn ? max_turn : (turn < -max_turn ? -max_turn : turn));
    const HeadingFrame now = heading_frame(heading);
    const HeadingFrame then = heading_frame(landing_heading);
    // Mean direction of travel over the swing.
    const vec3 travel = normalize3(now.forward + then.forward, now.forward);
    const vec3 root_then = root + travel * predicted.distance;
    const StepPlan next = step_plan(c, predicted.end_speed, g.commanded_speed, false);
    const float stance_time = next.duty * 2.0f * next.duration;
    float ahead = predicted.end_speed * stance_time * 0.5f;
    if (g.first_step) ahead *= 0.5f;
    const vec3 spot = root_then + then.forward * ahead + then.left * (side_sign(foot) * rig.hip_half_width);
    return place_foot_on_flat_spot(terrain, rig, spot.x, spot.z, then.forward);
}

// Standing spot for a foot beside the other (planted) foot.
Placement stop_target(const GaitState& g, int foot, float heading, const GaitRig& rig, const Terrain& terrain) {
    const HeadingFrame h = heading_frame(heading);
    const vec3 other = g.feet[static_cast<std::size_t>(1 - foot)].ankle;
    const vec3 spot = other + h.left * (side_sign(foot) * 2.0f * rig.hip_half_width);
    return place_foot_on_flat_spot(terrain, rig, spot.x, spot.z, h.forward);
}

}  // namespace

float stick_speed_fraction(float deflection, const SimConfig& c) {
    if (deflection <= c.stick_deadzone) return 0.0f;
    float d = (deflection - c.stick_deadzone) / (1.0f - c.stick_deadzone);
    d = clampf(d, 0.0f, 1.0f);
    return (1.0f - c.response_curve) * d + c.response_curve * d * d;
}

float slope_speed_multiplier(const Terrain& terrain, const SimConfig& c, float x, float z, float heading) {
    const vec3 n = query_ground(terrain, x, z).normal;
    const HeadingFrame h = heading_frame(heading);
    const float grade = n.y > 1e-3f ? -(n.x * h.forward.x + n.z * h.forward.z) / n.y : 0.0f;
    const double degrees = det::atan(std::fabs(static_cast<double>(grade))) * det::kRadToDeg;
    return clampf(1.0f - c.slope_speed_factor * static_cast<float>(degrees), 0.2f, 1.0f);
}

GaitRig make_gait_rig(const SimConfig& c) {
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

GaitState initial_gait_state(const SimConfig& c, const GaitRig& rig, const Terrain& terrain, vec3 root, float heading) {
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

void update_gait(GaitState& g, vec3& root, float& heading, vec2& velocity, const GaitTickInput& in, const SimConfig& c,
                 const GaitRig& rig, const Terrain& terrain) {
    const float dt = in.dt;
    // Stick → commanded speed and direction (stick up walks toward −Z).
    const float deflection = minf(1.0f, std::sqrt(in.stick_x * in.stick_x + in.stick_y * in.stick_y));
    const float fraction = stick_speed_fraction(deflection, c);
    const bool moving_command = fraction > 0.0f;
    float desired_heading = heading;
    if (moving_command) desired_heading = static_cast<float>(det::atan2(in.stick_x, -in.stick_y));
    const double diff = det::wrap_angle(static_cast<double>(desired_heading) - heading);
    const double abs_diff = diff < 0 ? -diff : diff;

    if (moving_command) {
        const std::int32_t was_turning = g.turning_in_place;
        if (abs_diff > c.turn_in_place_deg * det::kDegToRad) g.turning_in_place = 1;
        else if (abs_diff < 20.0 * det::kDegToRad) g.turning_in_place = 0;
        // Swings aimed for turning in place re-aim for walking off, and back.
        if (was_turning != g.turning_in_place)
            for (FootState& f : g.feet) {
                f.replanned = 0;
                f.planned_speed = -1.0f;
            }
        const double max_turn = c.turn_rate_deg_s * det::kDegToRad * dt;
        heading = static_cast<float>(det::wrap_angle(heading + (diff > max_turn ? max_turn : (diff < -max_turn ? -max_turn : diff))));
        g.commanded_speed = c.max_speed * fraction * slope_speed_multiplier(terrain, c, root.x, root.z, heading);
        if (g.turning_in_place) {
            g.speed = 0.0f;  // immediate: no walking backwards
        } else {
            const float dv = g.commanded_speed - g.speed;
            const float max_dv = c.acceleration * dt;
            g.speed += dv > max_dv ? max_dv : (dv < -max_dv ? -max_dv : dv);
        }
    } else {
        g.commanded_speed = 0.0f;
        g.speed = 0.0f;  // stopping is immediate in movement
        g.turning_in_place = 0;
    }
    const HeadingFrame h = heading_frame(heading);
    velocity = vec2(h.forward.x * g.speed, h.forward.z * g.speed);
    root.x += velocity.x * dt;
    root.z += velocity.y * dt;

    const bool wants_steps = moving_command && (g.speed > 0.0f || g.turning_in_place || abs_diff > 0.2);
    const StepPlan plan = step_plan(c, g.speed, g.commanded_speed, g.turning_in_place != 0);
    const float dphase = dt / (2.0f * plan.duration);

    // Mode changes.
    if (wants_steps && g.mode != GaitMode::stepping) {
        if (g.mode == GaitMode::idle) {
            // Lead with the foot on the side of the turn, else the left.
            const int lead = diff < -0.2 ? 1 : 0;
            g.cycle_phase = frac((lead == 0 ? 0.0f : 0.5f) + plan.duty);
            g.first_step = 1;
        }
        g.mode = GaitMode::stepping;
        for (FootState& f : g.feet) f.timed_rate = 0.0f;
    } else if (!wants_steps && g.mode == GaitMode::stepping) {
        g.mode = GaitMode::stopping;
        // A foot in the air re-aims beside the planted one and lands quickly.
        for (int i = 0; i < 2; ++i) {
            FootState& f = g.feet[static_cast<std::size_t>(i)];
            const FootState& other = g.feet[static_cast<std::size_t>(1 - i)];
            if (!f.swinging) continue;
            const float remaining = maxf(0.02f, (1.0f - f.progress) * (1.0f - f.lift_phase) * 2.0f * plan.duration);
            // In a flight phase neither foot is down to stand beside: both go under their hips.
            const vec3 spot = root + h.left * (side_sign(i) * rig.hip_half_width);
            const Placement p = other.swinging ? place_foot_on_flat_spot(terrain, rig, spot.x, spot.z, h.forward)
                                               : stop_target(g, i, heading, rig, terrain);
            // Short, but never faster than 3 m/s for the foot.
            const float time = clampf(maxf(remaining, horizontal_distance(f.ankle, p.ankle) / 3.0f), 0.15f, c.stop_transition_s);
            begin_swing(f, p, terrain, rig, 0.0f, 1.0f / time);
        }
    }

    // Advance swings and lift stance feet.
    const float blend_target = clampf((g.speed - c.run_threshold) / 0.6f + 0.5f, 0.0f, 1.0f);
    g.run_blend = approach(g.run_blend, blend_target, c.interpolation_rate, dt);
    if (g.mode == GaitMode::stepping) g.cycle_phase = frac(g.cycle_phase + dphase);
    // Where foot i, lifting (or re-aiming) at its phase psi, should land.
    const auto aim = [&](int i, float psi) {
        if (!g.turning_in_place) return plan_target(g, i, root, heading, desired_heading, c, rig, terrain, 1.0f - psi, dt);
        // Turning in place: small steps to the hip's spot under the turned heading.
        const float time_to_land = predict_landing(c, g.speed, g.commanded_speed, 1.0f - psi, true, dt).time;
        const double turn = det::wrap_angle(static_cast<double>(desired_heading) - heading);
        const double max_turn = c.turn_rate_deg_s * det::kDegToRad * time_to_land;
        const HeadingFrame then = heading_frame(heading + (turn > max_turn ? max_turn : (turn < -max_turn ? -max_turn : turn)));
        const vec3 spot = root + then.left * (side_sign(i) * rig.hip_half_width);
        return place_foot_on_flat_spot(terrain, rig, spot.x, spot.z, then.forward);
    };
    constexpr float kShortestSwing = 0.12f;  // s: a late lift-off still swings this long
    for (int i = 0; i < 2; ++i) {
        FootState& f = g.feet[static_cast<std::size_t>(i)];
        FootState& other = g.feet[static_cast<std::size_t>(1 - i)];
        if (f.swinging) {
            const float rate = f.timed_rate > 0.0f ? f.timed_rate * dt
                                                   : minf(dphase / maxf(1e-3f, 1.0f - f.lift_phase), dt / kShortestSwing);
            f.progress += rate;
            if (f.progress >= 1.0f) {
                land(f, g);
                g.first_step = 0;
            } else {
                // Re-aim once if the stick changed the landing spot a lot.
                const bool command_changed = std::fabs(g.commanded_speed - f.planned_speed) > 0.25f ||
                                             std::fabs(det::wrap_angle(static_cast<double>(desired_heading) - f.planned_heading)) > 0.25;
                if (g.mode == GaitMode::stepping && command_changed && !f.replanned && f.timed_rate == 0.0f && f.progress < 0.6f) {
                    const float psi = foot_phase(g.cycle_phase, i);
                    const Placement p = aim(i, psi);
                    if (horizontal_distance(p.ankle, f.target) > 0.06f) {
                        const float ground = f.ground;
                        begin_swing(f, p, terrain, rig, psi, 0.0f);
                        f.start_ground = ground;
                        f.replanned = 1;
                    }
                    f.planned_speed = g.commanded_speed;
                    f.planned_heading = desired_heading;
                }
                evaluate_swing(f, i, c, rig, g.run_blend, h.left);
            }
        } else if (g.mode == GaitMode::stepping) {
            const float psi = foot_phase(g.cycle_phase, i);
            const bool walking = !running(c, g.speed);
            if (psi >= plan.duty && (!walking || !other.swinging)) {
                begin_swing(f, aim(i, psi), terrain, rig, psi, 0.0f);
                f.planned_speed = g.commanded_speed;
                f.planned_heading = desired_heading;
                evaluate_swing(f, i, c, rig, g.run_blend, h.left);
            }
        }
    }
    if (g.mode == GaitMode::stopping && !g.feet[0].swinging && !g.feet[1].swinging) {
        // Both down: bring the trailing foot beside the other in one step, or rest.
        const float along = dot3(g.feet[0].ankle - g.feet[1].ankle, h.forward);
        if (std::fabs(along) > 0.05f) {
            const int trailing = along < 0.0f ? 0 : 1;
            const Placement p = stop_target(g, trailing, heading, rig, terrain);
            begin_swing(g.feet[static_cast<std::size_t>(trailing)], p, terrain, rig, 0.0f, 1.0f / maxf(0.25f, c.stop_transition_s * 1.5f));
            evaluate_swing(g.feet[static_cast<std::size_t>(trailing)], trailing, c, rig, g.run_blend, h.left);
        } else {
            g.mode = GaitMode::idle;
        }
    }
    const bool flight = g.feet[0].swinging && g.feet[1].swinging;
    if (flight && !g.flight_phases_open) ++g.flight_phases;
    g.flight_phases_open = flight ? 1 : 0;

    // Pelvis: over the root, at the mean foot height plus the configured height,
    // with the prototype's bob and sway, breathing when still; then lowered where
    // needed so both ankles stay within the IK's exact reach.
    g.activity = approach(g.activity, g.mode == GaitMode::idle ? 0.0f : clampf(g.speed / 1.0f, 0.0f, 1.0f), c.interpolation_rate, dt);
    if (g.mode == GaitMode::idle) {
        // Settle over the middle of the feet.
        const vec3 mid = 0.5f * (g.feet[0].ankle + g.feet[1].ankle);
        root.x = approach(root.x, mid.x, c.interpolation_rate, dt);
        root.z = approach(root.z, mid.z, c.interpolation_rate, dt);
    }
    const float ground_mean = 0.5f * (g.feet[0].ground + g.feet[1].ground);
    g.pelvis_base = approach(g.pelvis_base, ground_mean, c.interpolation_rate * 1.5f, dt);
    root.y = g.pelvis_base;
    const float step_phase = frac(2.0f * g.cycle_phase);
    const vec3 bob = blended_pelvis(rig, g.run_blend, step_phase) * g.activity;
    const float stance_side = g.cycle_phase < 0.5f ? 1.0f : -1.0f;  // left foot leads the first half
    const double breath = det::sin(det::kTwoPi * in.breath_time / c.breath_period_s);
    vec3 pelvis = root + h.left * (bob.x * stance_side) + h.forward * bob.z;
    pelvis.y = g.pelvis_base + c.gait_pelvis_height + bob.y + static_cast<float>(breath) * c.breath_amplitude * (1.0f - g.activity);
    for (int i = 0; i < 2; ++i) {
        const FootState& f = g.feet[static_cast<std::size_t>(i)];
        const vec3 hip = pelvis + h.left * (side_sign(i) * rig.hip_half_width);
        const float dx = f.ankle.x - hip.x, dz = f.ankle.z - hip.z;
        const float horizontal2 = dx * dx + dz * dz;
        const float reach2 = rig.leg_reach * rig.leg_reach;
        const float drop = std::sqrt(maxf(reach2 - horizontal2, 0.09f * reach2));
        // Swinging feet bind too: a leg beyond reach would snap toward straight.
        const float limit = f.ankle.y + drop;
        pelvis.y = minf(pelvis.y, limit);
    }
    g.pelvis = pelvis;
    const float lean_target = minf(c.max_spine_lean_deg, c.spine_lean_deg_per_m_s * g.speed) * static_cast<float>(det::kDegToRad);
    g.lean = approach(g.lean, lean_target, c.interpolation_rate, dt);
}

bool GaitPoseJob::validate() const {
    const std::size_t n = static_cast<std::size_t>(kPuppetJointCount);
    return gait && rig && config && parents.size() == n && rest_offsets.size() == n && local_rotations.size() == n &&
           local_translations.size() == n && model_rotations.size() >= n && model_positions.size() >= n;
}

void GaitPoseJob::run() const {
    const GaitState& g = *gait;
    const GaitRig& r = *rig;
    const SimConfig& c = *config;
    for (std::size_t j = 0; j < local_rotations.size(); ++j) {
        local_rotations[j] = quat_identity();
        local_translations[j] = rest_offsets[j];
    }
    const HeadingFrame h = heading_frame(heading);
    const quat yaw = quat_axis_angle(vec3(0.0f, 1.0f, 0.0f), heading);
    local_rotations[kPelvis] = yaw;
    local_translations[kPelvis] = g.pelvis;
    // Spine leans into the motion (spread over three joints), breathes when still;
    // neck and head take back half the lean so the gaze stays level.
    const double breath = det::sin(det::kTwoPi * breath_time / c.breath_period_s) * (1.0f - g.activity);
    const quat spine = quat_axis_angle(vec3(1.0f, 0.0f, 0.0f), g.lean / 3.0f - 0.01 * breath);
    local_rotations[kSpine1] = spine;
    local_rotations[kSpine2] = spine;
    local_rotations[kSpine3] = spine;
    const quat head = quat_axis_angle(vec3(1.0f, 0.0f, 0.0f), -0.25 * g.lean + 0.01 * breath);
    local_rotations[kNeck] = head;
    local_rotations[kHead] = head;

    // Legs: two-bone IK from each hip to its ankle, knees forward.
    const int thighs[2] = {kThighL, kThighR};
    for (int i = 0; i < 2; ++i) {
        const FootState& f = g.feet[static_cast<std::size_t>(i)];
        TwoBoneIkInput ik;
        ik.root = g.pelvis + h.left * (side_sign(i) * r.hip_half_width);
        ik.target = f.ankle;
        ik.pole = h.forward;
        ik.upper_length = r.thigh;
        ik.lower_length = r.shin;
        const TwoBoneIkResult s = solve_two_bone_ik(ik);
        const std::size_t thigh = static_cast<std::size_t>(thighs[i]);
        local_rotations[thigh] = quat_normalize(quat_mul(quat_conjugate(yaw), s.upper_rotation));
        local_rotations[thigh + 1] = quat_normalize(quat_mul(quat_conjugate(s.upper_rotation), s.lower_rotation));
        local_rotations[thigh + 2] = quat_normalize(quat_mul(quat_conjugate(s.lower_rotation), f.rotation));
    }
    LocalToModelJob fk{parents, local_rotations, local_translations, model_rotations, model_positions};
    fk.run();

    // Arms: the hands follow the blended hand paths, swinging against the legs;
    // elbows point back.
    const int clavicles[2] = {kClavicleL, kClavicleR};
    const float hang = 0.95f * (r.upper_arm + r.forearm);
    for (int i = 0; i < 2; ++i) {
        const std::size_t clavicle = static_cast<std::size_t>(clavicles[i]);
        const vec3 shoulder = model_positions[clavicle + 1];
        const vec3 path = blended_hand(r, g.run_blend, foot_phase(g.cycle_phase, i));
        const vec3 rest(0.03f, 0.0f, 0.02f);
        const vec3 offset = lerp(rest, path, g.activity);
        TwoBoneIkInput ik;
        ik.root = shoulder;
        ik.target = shoulder + h.left * (side_sign(i) * offset.x) + vec3(0.0f, offset.y - hang, 0.0f) + h.forward * offset.z;
        ik.pole = -h.forward + h.left * (side_sign(i) * 0.3f);
        ik.upper_length = r.upper_arm;
        ik.lower_length = r.forearm;
        ik.hinge_sign = -1.0f;
        const TwoBoneIkResult s = solve_two_bone_ik(ik);
        const quat clavicle_rotation = model_rotations[clavicle];
        local_rotations[clavicle + 1] = quat_normalize(quat_mul(quat_conjugate(clavicle_rotation), s.upper_rotation));
        local_rotations[clavicle + 2] = quat_normalize(quat_mul(quat_conjugate(s.upper_rotation), s.lower_rotation));
        // The hand continues the forearm.
    }
    fk.run();
}

}  // namespace marionette
