#include "runtime/matching/matching_controller.hpp"

#include <cmath>
#include <stdexcept>

#include "runtime/math/det_math.hpp"
#include "runtime/math/planar_alignment.hpp"

namespace marionette {

namespace {
constexpr float kLn2 = 0.69314718f;
constexpr int kNearAheadFrames = 3;  // a search answer this close ahead in the same clip is where the clip goes anyway

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
// 1 at u = 0 … 0 at u ≥ 1, with zero slope at both ends.
float cubic_decay(float u) { return u >= 1.0f ? 0.0f : 1.0f - u * u * (3.0f - 2.0f * u); }
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
}

bool MatchingController::valid(const MatchingState& s, LocalPoseOutput pose) const {
    const size_t n = static_cast<size_t>(db_.joint_count);
    return pose.rotations.size() == n && pose.translations.size() == n && s.frame >= 0 && s.frame < db_.frame_count &&
           s.frame_time >= 0.0f && s.frame_time < 1.0f;
}

MatchingState MatchingController::initial_state(vec3 position, float heading) const {
    MatchingState s;
    while (!db_.searchable[static_cast<size_t>(s.frame)]) ++s.frame;
    for (quat& q : s.offset_rotation) q = quat_identity();
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
    for (quat& q : s.offset_rotation) q = quat_identity();
    for (vec3& t : s.offset_translation) t = vec3(0.0f);
    s.since_jump = 1e6f;
    s.since_search = 1e6f;  // search at the first tick
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
    const float decay = offsets ? cubic_decay(s.since_jump / config_.inertialization_s) : 0.0f;
    for (size_t j = 0; j < n; ++j) {
        quat r = nlerp(source_.rotations[f0 + j], source_.rotations[f1 + j], s.frame_time);
        vec3 t = lerp(source_.translations[f0 + j], source_.translations[f1 + j], s.frame_time) * source_.metres_per_unit;
        if (j == 0) {
            t = apply_planar(world, t);
            r = quat_mul(planar_rotation(world), r);
        }
        if (decay > 0.0f) {
            r = quat_mul(nlerp(quat_identity(), s.offset_rotation[j], decay), r);
            t += s.offset_translation[j] * decay;
        }
        out.rotations[j] = r;
        out.translations[j] = t;
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
    const vec3 r = root_position(s);
    const float h = root_heading(s);
    s.frame = frame;
    s.frame_time = 0.0f;
    MatchingState clip_only = s;
    clip_only.world_angle = clip_only.world_dx = clip_only.world_dz = 0.0;
    const PlanarTransform w = placement(root_position(clip_only), root_heading(clip_only), r, h);
    s.world_angle = w.angle, s.world_dx = w.dx, s.world_dz = w.dz;
    s.since_jump = 0.0f;
    // Offsets: shown pose = offset · new pose (rotations), shown − new (translations).
    MatchingState bare = s;
    bare.since_jump = 1e6f;
    std::array<quat, kMatchMaxJoints> rot{};
    std::array<vec3, kMatchMaxJoints> tr{};
    sample(bare, {std::span<quat>(rot.data(), n), std::span<vec3>(tr.data(), n)}, false);
    for (size_t j = 0; j < n; ++j) {
        quat o = quat_mul(shown_rotations_[j], quat_conjugate(rot[j]));
        if (o.w < 0.0f) o = quat(-o.w, -o.x, -o.y, -o.z);
        s.offset_rotation[j] = quat_normalize(o);
        s.offset_translation[j] = shown_translations_[j] - tr[j];
    }
    ++s.jumps;
}

bool MatchingController::step(MatchingState& s, const MatchingInput& in, LocalPoseOutput out) {
    if (!valid(s, out) || !(in.dt >= 0.0f)) return false;
    s.spring = advance_trajectory(s.spring, in.goal, config_.velocity_halflife_s, config_.facing_halflife_s, in.dt);
    s.frame_time += in.dt * static_cast<float>(db_.frame_rate);
    bool at_end = false;
    while (s.frame_time >= 1.0f) {
        if (s.frame + 1 < db_.clip_end[static_cast<size_t>(s.frame)] - 1) {
            ++s.frame;
            s.frame_time -= 1.0f;
        } else {
            s.frame = db_.clip_end[static_cast<size_t>(s.frame)] - 2 < 0 ? 0 : db_.clip_end[static_cast<size_t>(s.frame)] - 2;
            s.frame_time = 0.999f;
            at_end = true;
            break;
        }
    }
    correct_root(s, in.dt);
    s.since_search += in.dt;
    s.since_jump += in.dt;
    const bool due = s.since_search >= config_.search_interval_s;
    const bool departed = s.since_search >= 0.25f * config_.search_interval_s &&
                          trajectory_departure(s, in.goal) > config_.search_threshold_m;
    if (due || departed || at_end) {
        std::array<float, kMatchFeatureCount> raw{}, query{};
        desired_features(s, in.goal, raw);
        db_.normalise(raw, query);
        MatchingResult best;
        if (db_.searchable[static_cast<size_t>(s.frame)] && !at_end) best = {s.frame, matching_cost(db_, query, s.frame)};
        best = search_matching_accelerated(db_, query, best);
        s.since_search = 0.0f;
        ++s.searches;
        s.last_cost = best.cost;
        const bool same_clip = db_.clip_end[static_cast<size_t>(best.frame)] == db_.clip_end[static_cast<size_t>(s.frame)];
        const bool just_ahead = same_clip && best.frame > s.frame && best.frame - s.frame <= kNearAheadFrames;
        if (best.frame >= 0 && best.frame != s.frame && !just_ahead) jump(s, best.frame);
    }
    const size_t sf = static_cast<size_t>(db_.source_frame[static_cast<size_t>(s.frame)]);
    s.contacts = source_.contacts[s.frame_time < 0.5f || s.frame + 1 >= db_.clip_end[static_cast<size_t>(s.frame)] ? sf : sf + 1];
    sample(s, out, true);
    return true;
}

}  // namespace marionette
