#include "runtime/matching/matching_controller.hpp"

#include <cmath>
#include <stdexcept>

#include "runtime/math/det_math.hpp"
#include "runtime/math/planar_alignment.hpp"

namespace marionette {

namespace {
constexpr float kLn2 = 0.69314718f;
// A search answer this close (frames) ahead of the current frame in the same
// clip is where the clip goes anyway; with the stick at rest, one this close
// behind replays what was just shown: jumping back a few frames at every search
// looped three frames of a stop for seconds, and the feet slid by the loop's
// root motion. (Moving, the jump back stays: refusing it raised the CMU
// database's joint speeds on circle and run to 1,505-1,908 deg/s.)
constexpr int kNearFrames = 3;
// A clip whose last frame's hips move slower than this (m/s, horizontally) ends
// at rest: with the stick at rest it holds that pose (rests_at_end).
constexpr float kRestHipsSpeed = 0.15f;

bool goal_at_rest(const TrajectoryGoal& goal) { return goal.vx * goal.vx + goal.vz * goal.vz < 1e-6f; }

// Whether the clip `frame` is in ends at rest: its last frame's hips move slower than kRestHipsSpeed.
bool rests_at_end(const MatchingDatabase& db, int frame) {
    const float* last = db.frame_raw(db.clip_end[static_cast<size_t>(frame)] - 1);
    const float vx = last[kMatchGroupBegin[kMatchHipsVelocity]], vz = last[kMatchGroupBegin[kMatchHipsVelocity] + 2];
    return vx * vx + vz * vz < kRestHipsSpeed * kRestHipsSpeed;
}

quat nlerp(quat a, quat b, float t) {
    if (quat_dot(a, b) < 0.0f) b = quat(-b.w, -b.x, -b.y, -b.z);
    const float s = 1.0f - t;
    return quat_normalize(quat(s * a.w + t * b.w, s * a.x + t * b.x, s * a.y + t * b.y, s * a.z + t * b.z));
}
float heading_of(quat r, double facing_offset) {
    const vec3 forward = quat_rotate(r, vec3(0.0f, 0.0f, 1.0f));
    return static_cast<float>(det::wrap_angle(det::atan2(forward.x, forward.z) + facing_offset));
}
// The placement taking clip point `c` facing `clip_heading` to world point `p` facing `heading`.
PlanarTransform placement(vec3 c, float clip_heading, vec3 p, float heading) {
    const double angle = det::wrap_angle(static_cast<double>(heading) - clip_heading);
    double sn = 0.0, cs = 0.0;
    det::sin_cos(angle, sn, cs);
    return {angle, p.x - (cs * c.x + sn * c.z), p.z - (-sn * c.x + cs * c.z)};
}
// Rotation vector (axis × angle, radians, angle ≤ π) of a unit quaternion; owned atan2, no libm.
vec3 rotation_vector(quat q) {
    if (q.w < 0.0f) q = quat(-q.w, -q.x, -q.y, -q.z);
    const double s = std::sqrt(static_cast<double>(q.x) * q.x + static_cast<double>(q.y) * q.y + static_cast<double>(q.z) * q.z);
    if (s < 1e-9) return vec3(2.0f * q.x, 2.0f * q.y, 2.0f * q.z);
    const float k = static_cast<float>(2.0 * det::atan2(s, static_cast<double>(q.w)) / s);
    return vec3(q.x * k, q.y * k, q.z * k);
}
// The unit quaternion of a rotation vector; owned sin/cos.
quat from_rotation_vector(vec3 v) {
    const double angle = std::sqrt(static_cast<double>(v.x) * v.x + static_cast<double>(v.y) * v.y + static_cast<double>(v.z) * v.z);
    if (angle < 1e-9) return quat_normalize(quat(1.0f, 0.5f * v.x, 0.5f * v.y, 0.5f * v.z));
    double sn = 0.0, cs = 0.0;
    det::sin_cos(0.5 * angle, sn, cs);
    const float k = static_cast<float>(sn / angle);
    return quat(static_cast<float>(cs), v.x * k, v.y * k, v.z * k);
}
// One critically damped spring toward zero (x offset, v its velocity), y = 2 ln2 / halflife.
void decay_spring(vec3& x, vec3& v, float y, float e, float dt) {
    const vec3 j1 = v + x * y;
    x = (x + j1 * dt) * e;
    v = (v - j1 * (y * dt)) * e;
}
}  // namespace

MatchingController::MatchingController(const MatchingSource& source, const MatchingDatabase& db,
                                       const MatchingControllerConfig& config)
    : source_(source), db_(db), config_(config) {
    const int n = source.joint_count();
    if (n <= 0 || n > kMatchMaxJoints || n != db.joint_count)
        throw std::invalid_argument("matching: the database's joint count is not the source's, or over 64");
    if (db.frame_count <= 0 || db.frame_count != static_cast<int>(db.source_frame.size()))
        throw std::invalid_argument("matching: the database has no frames");
    const size_t frames = source.rotations.size() / static_cast<size_t>(n);
    for (std::int32_t f : db.source_frame)
        if (f < 0 || static_cast<size_t>(f) >= frames) throw std::invalid_argument("matching: a database frame is not in the source");
    bool any = false;
    for (std::uint8_t s : db.searchable) any = any || s != 0;
    if (!any) throw std::invalid_argument("matching: no database frame can be searched (clips too short)");
    shown_rotations_.resize(static_cast<size_t>(n));
    shown_translations_.resize(static_cast<size_t>(n));
    old_angular_.resize(static_cast<size_t>(n));
    old_linear_.resize(static_cast<size_t>(n));
}

bool MatchingController::valid(const MatchingState& s, LocalPoseOutput pose) const {
    const size_t n = static_cast<size_t>(db_.joint_count);
    return pose.rotations.size() == n && pose.translations.size() == n && s.frame >= 0 && s.frame < db_.frame_count &&
           s.frame_time >= 0.0f && s.frame_time < 1.0f;
}

MatchingState MatchingController::initial_state(vec3 position, float heading) const {
    MatchingState s;
    while (!db_.searchable[static_cast<size_t>(s.frame)]) ++s.frame;
    place(s, position, heading);
    return s;
}

void MatchingController::place(MatchingState& s, vec3 position, float heading) const {
    const MatchingState clip_only = [&] {
        MatchingState c = s;
        c.world_angle = c.world_dx = c.world_dz = 0.0;
        return c;
    }();
    const PlanarTransform w = placement(root_position(clip_only), root_heading(clip_only), position, heading);
    s.world_angle = w.angle, s.world_dx = w.dx, s.world_dz = w.dz;
    s.spring = TrajectorySpring{};
    s.spring.px = position.x, s.spring.pz = position.z, s.spring.heading = heading;
    for (auto* a : {&s.offset_rotation, &s.offset_angular_velocity, &s.offset_translation, &s.offset_velocity})
        for (vec3& v : *a) v = vec3(0.0f);
    s.since_jump = 1e6f;
    s.since_search = 1e6f;  // search at the first tick
    s.action = -1;
}

vec3 MatchingController::root_position(const MatchingState& s) const {
    const size_t n = static_cast<size_t>(db_.joint_count);
    const size_t f0 = static_cast<size_t>(db_.source_frame[static_cast<size_t>(s.frame)]);
    const size_t f1 = s.frame + 1 < db_.clip_end[static_cast<size_t>(s.frame)]
                          ? static_cast<size_t>(db_.source_frame[static_cast<size_t>(s.frame) + 1]) : f0;
    const vec3 t = lerp(source_.translations[f0 * n], source_.translations[f1 * n], s.frame_time) * source_.metres_per_unit;
    return apply_planar({s.world_angle, s.world_dx, s.world_dz}, t);
}

float MatchingController::root_heading(const MatchingState& s) const {
    const size_t n = static_cast<size_t>(db_.joint_count);
    const size_t f0 = static_cast<size_t>(db_.source_frame[static_cast<size_t>(s.frame)]);
    const size_t f1 = s.frame + 1 < db_.clip_end[static_cast<size_t>(s.frame)]
                          ? static_cast<size_t>(db_.source_frame[static_cast<size_t>(s.frame) + 1]) : f0;
    const quat r = nlerp(source_.rotations[f0 * n], source_.rotations[f1 * n], s.frame_time);
    return static_cast<float>(det::wrap_angle(static_cast<double>(heading_of(r, source_.facing_offset)) + s.world_angle));
}

void MatchingController::sample(const MatchingState& s, LocalPoseOutput out, bool offsets) const {
    const size_t n = static_cast<size_t>(db_.joint_count);
    const size_t f0 = static_cast<size_t>(db_.source_frame[static_cast<size_t>(s.frame)]) * n;
    const size_t f1 = (s.frame + 1 < db_.clip_end[static_cast<size_t>(s.frame)]
                           ? static_cast<size_t>(db_.source_frame[static_cast<size_t>(s.frame) + 1]) : f0 / n) * n;
    const PlanarTransform world{s.world_angle, s.world_dx, s.world_dz};
    const bool offset = offsets && offsets_live(s);
    for (size_t j = 0; j < n; ++j) {
        quat r = nlerp(source_.rotations[f0 + j], source_.rotations[f1 + j], s.frame_time);
        vec3 t = lerp(source_.translations[f0 + j], source_.translations[f1 + j], s.frame_time) * source_.metres_per_unit;
        if (j == 0) {
            t = apply_planar(world, t);
            r = quat_mul(planar_rotation(world), r);
        }
        if (offset) {
            r = quat_normalize(quat_mul(from_rotation_vector(s.offset_rotation[j]), r));
            t += s.offset_translation[j];
        }
        out.rotations[j] = r;
        out.translations[j] = t;
    }
}

void MatchingController::frame_velocities(const MatchingState& s, std::span<vec3> angular, std::span<vec3> linear) const {
    const size_t n = static_cast<size_t>(db_.joint_count);
    const size_t f0 = static_cast<size_t>(db_.source_frame[static_cast<size_t>(s.frame)]) * n;
    const size_t f1 = (s.frame + 1 < db_.clip_end[static_cast<size_t>(s.frame)]
                           ? static_cast<size_t>(db_.source_frame[static_cast<size_t>(s.frame) + 1]) : f0 / n) * n;
    const float rate = static_cast<float>(db_.frame_rate);
    const quat world = planar_rotation({s.world_angle, s.world_dx, s.world_dz});
    for (size_t j = 0; j < n; ++j) {
        const quat step = quat_mul(source_.rotations[f1 + j], quat_conjugate(source_.rotations[f0 + j]));
        vec3 w = rotation_vector(step) * rate;
        vec3 v = (source_.translations[f1 + j] - source_.translations[f0 + j]) * (source_.metres_per_unit * rate);
        if (j == 0) w = quat_rotate(world, w), v = quat_rotate(world, v);
        angular[j] = w;
        linear[j] = v;
    }
}

void MatchingController::decay_offsets(MatchingState& s, float dt) const {
    if (!offsets_live(s)) return;
    const float y = 2.0f * kLn2 / (config_.inertialization_s / 3.0f);
    const float e = approx_negexp(y * dt);
    for (size_t j = 0; j < static_cast<size_t>(db_.joint_count); ++j) {
        decay_spring(s.offset_rotation[j], s.offset_angular_velocity[j], y, e, dt);
        decay_spring(s.offset_translation[j], s.offset_velocity[j], y, e, dt);
    }
}

bool MatchingController::pose(const MatchingState& s, LocalPoseOutput out) const {
    if (!valid(s, out)) return false;
    sample(s, out, true);
    return true;
}

void MatchingController::correct_root(MatchingState& s, float dt) const {
    const vec3 r = root_position(s);
    const float h = root_heading(s);
    const float a = 1.0f - approx_negexp(kLn2 / config_.correction_halflife_s * dt);
    const vec3 target(r.x + (s.spring.px - r.x) * a, r.y, r.z + (s.spring.pz - r.z) * a);
    const double turn = det::wrap_angle(static_cast<double>(s.spring.heading) - h) * a;
    double sn = 0.0, cs = 0.0;
    det::sin_cos(turn, sn, cs);
    const PlanarTransform about{turn, target.x - (cs * r.x + sn * r.z), target.z - (-sn * r.x + cs * r.z)};
    const PlanarTransform w = compose_planar(about, {s.world_angle, s.world_dx, s.world_dz});
    s.world_angle = w.angle, s.world_dx = w.dx, s.world_dz = w.dz;
}

void MatchingController::desired_features(const MatchingState& s, const TrajectoryGoal& goal, std::span<float> raw) const {
    const float* own = db_.frame_raw(s.frame);
    for (size_t k = 0; k < kMatchFeatureCount; ++k) raw[k] = own[k];
    const vec3 r = root_position(s);
    double sn = 0.0, cs = 0.0;
    det::sin_cos(root_heading(s), sn, cs);
    for (size_t k = 0; k < kMatchTrajectoryPoints; ++k) {
        const float t = static_cast<float>(db_.trajectory_frames[k] / db_.frame_rate);
        const TrajectorySpring p = advance_trajectory(s.spring, goal, config_.velocity_halflife_s, config_.facing_halflife_s, t);
        const vec3 pos = to_root_frame(vec3(p.px - r.x, 0.0f, p.pz - r.z), sn, cs);
        double fs = 0.0, fc = 0.0;
        det::sin_cos(p.heading, fs, fc);
        const vec3 dir = to_root_frame(vec3(static_cast<float>(fs), 0.0f, static_cast<float>(fc)), sn, cs);
        raw[static_cast<size_t>(kMatchGroupBegin[kMatchTrajectoryPosition]) + 2 * k] = pos.x;
        raw[static_cast<size_t>(kMatchGroupBegin[kMatchTrajectoryPosition]) + 2 * k + 1] = pos.z;
        raw[static_cast<size_t>(kMatchGroupBegin[kMatchTrajectoryFacing]) + 2 * k] = dir.x;
        raw[static_cast<size_t>(kMatchGroupBegin[kMatchTrajectoryFacing]) + 2 * k + 1] = dir.z;
    }
}

float MatchingController::trajectory_departure(const MatchingState& s, const TrajectoryGoal& goal) const {
    std::array<float, kMatchFeatureCount> raw{};
    desired_features(s, goal, raw);
    const float* own = db_.frame_raw(s.frame);
    float worst = 0.0f;
    for (size_t k = 0; k < kMatchTrajectoryPoints; ++k) {
        const size_t i = static_cast<size_t>(kMatchGroupBegin[kMatchTrajectoryPosition]) + 2 * k;
        const float dx = raw[i] - own[i], dz = raw[i + 1] - own[i + 1];
        const float d = std::sqrt(dx * dx + dz * dz);
        if (d > worst) worst = d;
    }
    return worst;
}

void MatchingController::jump(MatchingState& s, int frame) {
    const size_t n = static_cast<size_t>(db_.joint_count);
    sample(s, {shown_rotations_, shown_translations_}, true);
    // The shown pose's velocity: the old frame's plus its offsets' (their sum, as Holden's inertialization).
    frame_velocities(s, old_angular_, old_linear_);
    const bool live = offsets_live(s);
    for (size_t j = 0; j < n; ++j) {
        if (live) old_angular_[j] += s.offset_angular_velocity[j], old_linear_[j] += s.offset_velocity[j];
    }
    const vec3 r = root_position(s);
    const float h = root_heading(s);
    s.frame = frame;
    s.frame_time = 0.0f;
    MatchingState clip_only = s;
    clip_only.world_angle = clip_only.world_dx = clip_only.world_dz = 0.0;
    const PlanarTransform w = placement(root_position(clip_only), root_heading(clip_only), r, h);
    s.world_angle = w.angle, s.world_dx = w.dx, s.world_dz = w.dz;
    s.since_jump = 0.0f;
    // Offsets: shown pose = exp(offset) · new pose (rotations), shown − new
    // (translations); their velocities: the shown pose's − the new frame's.
    std::array<quat, kMatchMaxJoints> rot{};
    std::array<vec3, kMatchMaxJoints> tr{}, new_angular{}, new_linear{};
    sample(s, {std::span<quat>(rot.data(), n), std::span<vec3>(tr.data(), n)}, false);
    frame_velocities(s, std::span<vec3>(new_angular.data(), n), std::span<vec3>(new_linear.data(), n));
    for (size_t j = 0; j < n; ++j) {
        s.offset_rotation[j] = rotation_vector(quat_normalize(quat_mul(shown_rotations_[j], quat_conjugate(rot[j]))));
        s.offset_angular_velocity[j] = old_angular_[j] - new_angular[j];
        s.offset_translation[j] = shown_translations_[j] - tr[j];
        s.offset_velocity[j] = old_linear_[j] - new_linear[j];
    }
    ++s.jumps;
}

bool MatchingController::step(MatchingState& s, const MatchingInput& in, LocalPoseOutput out) {
    if (!valid(s, out) || !(in.dt >= 0.0f)) return false;
    s.spring = advance_trajectory(s.spring, in.goal, config_.velocity_halflife_s, config_.facing_halflife_s, in.dt);
    if (in.action >= 0 && s.action < 0 && static_cast<size_t>(in.action) < db_.action_begin.size()) {
        jump(s, db_.action_begin[static_cast<size_t>(in.action)]);
        s.action = in.action;
    }
    s.frame_time += in.dt * static_cast<float>(db_.frame_rate);
    bool at_end = false;
    while (s.frame_time >= 1.0f) {
        if (s.frame + 1 < db_.clip_end[static_cast<size_t>(s.frame)] - 1) {
            ++s.frame;
            s.frame_time -= 1.0f;
        } else {
            s.frame = db_.clip_end[static_cast<size_t>(s.frame)] - 2 < 0 ? 0 : db_.clip_end[static_cast<size_t>(s.frame)] - 2;
            s.frame_time = 0.999f;
            // A clip that ends at rest holds its last pose while the stick is at
            // rest (searches still run, that pose the one to beat); else the end
            // forces a jump.
            at_end = s.action >= 0 || !(goal_at_rest(in.goal) && rests_at_end(db_, s.frame));
            break;
        }
    }
    decay_offsets(s, in.dt);
    const bool acting = s.action >= 0;
    if (!acting) {
        correct_root(s, in.dt);
    } else {
        // The action's own root motion plays; the stick's spring waits at the root.
        const vec3 r = root_position(s);
        s.spring = TrajectorySpring{};
        s.spring.px = r.x, s.spring.pz = r.z, s.spring.heading = root_heading(s);
    }
    s.since_search += in.dt;
    s.since_jump += in.dt;
    const bool due = !acting && s.since_search >= config_.search_interval_s;
    const bool departed = !acting && s.since_search >= 0.25f * config_.search_interval_s &&
                          trajectory_departure(s, in.goal) > config_.search_threshold_m;
    if (due || departed || at_end) {
        std::array<float, kMatchFeatureCount> raw{}, query{};
        desired_features(s, in.goal, raw);
        db_.normalise(raw, query);
        MatchingResult best;
        // The current frame is the one to beat where a jump could land, and also
        // in the last 1/3 s of a clip that ends at rest while the stick is at rest
        // (else the search jumped back to the last landable frame every time and
        // looped the stop's end, the feet sliding by the loop's root motion).
        const bool may_stay = db_.searchable[static_cast<size_t>(s.frame)] || (goal_at_rest(in.goal) && rests_at_end(db_, s.frame));
        if (may_stay && !at_end) best = {s.frame, matching_cost(db_, query, s.frame)};
        best = search_matching_accelerated(db_, query, best);
        s.since_search = 0.0f;
        ++s.searches;
        s.last_cost = best.cost;
        const bool same_clip = db_.clip_end[static_cast<size_t>(best.frame)] == db_.clip_end[static_cast<size_t>(s.frame)];
        const bool ahead = best.frame > s.frame && best.frame - s.frame <= kNearFrames;
        const bool behind = best.frame < s.frame && s.frame - best.frame <= kNearFrames && goal_at_rest(in.goal);
        const bool near = same_clip && (ahead || behind);
        if (best.frame >= 0 && best.frame != s.frame && !near) jump(s, best.frame);
        s.action = -1;  // an action ends at its clip's end, back in the locomotion
    }
    const size_t sf = static_cast<size_t>(db_.source_frame[static_cast<size_t>(s.frame)]);
    s.contacts = source_.contacts[s.frame_time < 0.5f || s.frame + 1 >= db_.clip_end[static_cast<size_t>(s.frame)] ? sf : sf + 1];
    sample(s, out, true);
    return true;
}

}  // namespace marionette
