// Foot contacts: detected on the source (low and slow), pinned on the puppet by
// two-bone IK, and measured (how far a pinned point moves within its run).
#include <algorithm>
#include <cmath>

#include "retarget/retarget_detail.hpp"
#include "runtime/anim/two_bone_ik.hpp"

namespace marionette::retarget::detail {

namespace {

const int kFootRole[2] = {role::foot_l, role::foot_r};

// Per frame and foot: 0 free, 1 ankle planted, 2 ball planted (heel lifted).
std::vector<unsigned char> detect(const ModelFrames& m, const HumanoidChains& h, const SourceToPuppet& sp,
                                  const RetargetOptions& o, float leg, double rate) {
    const int frames = static_cast<int>(m.positions.size() / static_cast<size_t>(m.points));
    std::vector<vec3> ankle(static_cast<size_t>(frames) * 2), ball(ankle.size());
    for (int f = 0; f < frames; ++f)
        for (int foot = 0; foot < 2; ++foot) {
            const size_t u = static_cast<size_t>(kFootRole[foot]);
            ankle[at(f, 2, foot)] = sp.apply(m.position(f, h.joint[u]));
            ball[at(f, 2, foot)] = sp.apply(point_of(m, f, h.to[u]));
        }
    float floor_a = ankle[0].y, floor_b = ball[0].y;
    for (size_t i = 0; i < ankle.size(); ++i) {
        floor_a = std::min(floor_a, ankle[i].y);
        floor_b = std::min(floor_b, ball[i].y);
    }
    const auto planted = [&](const std::vector<vec3>& p, float floor, int f, int foot) {
        const int a = std::max(f - 1, 0), b = std::min(f + 1, frames - 1);
        const vec3 d = p[at(b, 2, foot)] - p[at(a, 2, foot)];
        const float speed = b > a ? std::sqrt(d.x * d.x + d.z * d.z) * static_cast<float>(rate) / static_cast<float>(b - a) : 0.0f;
        return p[at(f, 2, foot)].y - floor < o.contact_height * leg && speed < o.contact_speed * leg;
    };
    std::vector<unsigned char> kind(ankle.size(), 0);
    for (int f = 0; f < frames; ++f)
        for (int foot = 0; foot < 2; ++foot)
            kind[at(f, 2, foot)] = planted(ankle, floor_a, f, foot) ? 1 : (planted(ball, floor_b, f, foot) ? 2 : 0);
    // Runs shorter than min_contact_s are not contacts.
    const int min_run = std::max(2, static_cast<int>(o.min_contact_s * rate + 0.5));
    for (int foot = 0; foot < 2; ++foot)
        for (int f = 0; f < frames;) {
            if (kind[at(f, 2, foot)] == 0) {
                ++f;
                continue;
            }
            int e = f;
            while (e < frames && kind[at(e, 2, foot)] != 0) ++e;
            if (e - f < min_run)
                for (int k = f; k < e; ++k) kind[at(k, 2, foot)] = 0;
            f = e;
        }
    return kind;
}

struct FootState {
    int pin_kind = 0;
    vec3 pin{0.0f};
    vec3 last_offset{0.0f};
    vec3 release_offset{0.0f};
    int release_left = 0;
};

// The ankle's target this frame (false: none), from the foot's contact kind.
bool ankle_target(FootState& s, int kind, vec3 ankle, vec3 foot_vector, int release_frames, vec3& target) {
    const float w = s.release_left > 0 ? static_cast<float>(s.release_left) / static_cast<float>(release_frames) : 0.0f;
    const vec3 free = ankle + s.release_offset * w;
    bool has = true;
    if (kind == 1) {
        if (s.pin_kind != 1) s.pin = s.pin_kind == 2 ? s.pin - foot_vector : free;
        target = s.pin;
        s.release_left = 0;
    } else if (kind == 2) {
        if (s.pin_kind != 2) s.pin = s.pin_kind == 1 ? s.pin + foot_vector : free + foot_vector;
        target = s.pin - foot_vector;
        s.release_left = 0;
    } else {
        if (s.pin_kind != 0) {
            s.release_offset = s.last_offset;
            s.release_left = release_frames;
        }
        const float wr = s.release_left > 0 ? static_cast<float>(s.release_left) / static_cast<float>(release_frames) : 0.0f;
        target = ankle + s.release_offset * wr;
        has = s.release_left > 0;
        if (s.release_left > 0) --s.release_left;
    }
    s.pin_kind = kind;
    s.last_offset = target - ankle;
    return has;
}

// Two-bone IK on one leg of frame f: thigh and shin swung onto the solution,
// the foot's world rotation kept.
void solve_leg(Clip& c, int f, int thigh, vec3 target, const std::vector<quat>& wr, const std::vector<vec3>& wp) {
    const int n = c.joint_count();
    const int shin = thigh + 1, foot = thigh + 2;
    const vec3 hip = wp[static_cast<size_t>(thigh)], knee = wp[static_cast<size_t>(shin)], ankle = wp[static_cast<size_t>(foot)];
    vec3 axis, pole;
    if (!unit(target - hip, axis)) return;
    const vec3 kv = knee - hip;
    if (!unit(kv - axis * glm::dot(kv, axis), pole)) pole = quat_rotate(wr[role::pelvis], vec3(0.0f, 0.0f, 1.0f));
    TwoBoneIkResult res;
    TwoBoneIkJob job;
    job.root = hip;
    job.target = target;
    job.pole = pole;
    job.upper_length = glm::length(c.skeleton.rest_offsets[static_cast<size_t>(shin)]);
    job.lower_length = glm::length(c.skeleton.rest_offsets[static_cast<size_t>(foot)]);
    job.soft_reach_start = 1.0f;
    job.result = &res;
    if (!job.run()) return;
    vec3 old_t, new_t, old_s, new_s;
    if (!unit(knee - hip, old_t) || !unit(res.mid - hip, new_t) || !unit(ankle - knee, old_s) || !unit(res.end - res.mid, new_s))
        return;
    const quat wt = quat_normalize(quat_mul(quat_from_to(old_t, new_t), wr[static_cast<size_t>(thigh)]));
    const quat ws = quat_normalize(quat_mul(quat_from_to(old_s, new_s), wr[static_cast<size_t>(shin)]));
    c.rotations[at(f, n, thigh)] = quat_normalize(quat_mul(quat_conjugate(wr[role::pelvis]), wt));
    c.rotations[at(f, n, shin)] = quat_normalize(quat_mul(quat_conjugate(wt), ws));
    c.rotations[at(f, n, foot)] = quat_normalize(quat_mul(quat_conjugate(ws), wr[static_cast<size_t>(foot)]));
}

void frame_fk(const Clip& c, int f, std::vector<quat>& wr, std::vector<vec3>& wp) {
    const size_t n = static_cast<size_t>(c.joint_count());
    const LocalToModelJob fk{c.skeleton.parents,
                             {std::span<const quat>(c.frame_rotations(f), n), std::span<const vec3>(c.frame_translations(f), n)},
                             {wr, wp}};
    expect_job_ran(fk.run());
}

void pin_feet(Clip& c, const std::vector<unsigned char>& kind, const RetargetOptions& o, ContactReport& report) {
    const int n = c.joint_count();
    const int release_frames = std::max(1, static_cast<int>(o.release_s * c.frame_rate + 0.5));
    FootState feet[2];
    std::vector<quat> wr(static_cast<size_t>(n));
    std::vector<vec3> wp(static_cast<size_t>(n));
    const int thighs[2] = {role::thigh_l, role::thigh_r};
    for (int f = 0; f < c.frame_count; ++f) {
        frame_fk(c, f, wr, wp);
        vec3 target[2];
        bool has[2];
        float drop = 0.0f;
        for (int foot = 0; foot < 2; ++foot) {
            const int t = thighs[foot];
            const vec3 ankle = wp[static_cast<size_t>(t + 2)];
            has[foot] = ankle_target(feet[foot], kind[at(f, 2, foot)], ankle, wp[static_cast<size_t>(t + 3)] - ankle, release_frames,
                                     target[foot]);
            if (!has[foot]) continue;
            // Out of reach: lower the pelvis until the leg reaches.
            const float reach = 0.9999f * (glm::length(c.skeleton.rest_offsets[static_cast<size_t>(t + 1)]) +
                                           glm::length(c.skeleton.rest_offsets[static_cast<size_t>(t + 2)]));
            const vec3 d = target[foot] - wp[static_cast<size_t>(t)];
            const float horiz2 = d.x * d.x + d.z * d.z;
            if (glm::dot(d, d) > reach * reach && horiz2 < reach * reach)
                drop = std::max(drop, -d.y - std::sqrt(reach * reach - horiz2));
        }
        if (drop > 0.0f) {
            c.translations[at(f, n, 0)].y -= drop;
            for (vec3& p : wp) p.y -= drop;
            report.max_root_drop_m = std::max(report.max_root_drop_m, static_cast<double>(drop));
        }
        for (int foot = 0; foot < 2; ++foot)
            if (has[foot]) solve_leg(c, f, thighs[foot], target[foot], wr, wp);
    }
}

// Largest movement of the pinned point (ankle for kind 1, ball for kind 2)
// within each run of one kind; returns the largest, adds runs to the report.
double measure_drift(const Clip& c, const std::vector<unsigned char>& kind, ContactReport* report) {
    const ModelFrames m = model_frames(c);
    double worst = 0.0, sum = 0.0;
    int runs = 0, frames = 0;
    const int ankles[2] = {role::foot_l, role::foot_r};
    for (int foot = 0; foot < 2; ++foot)
        for (int f = 0; f < c.frame_count;) {
            const int k = kind[at(f, 2, foot)];
            if (k == 0) {
                ++f;
                continue;
            }
            const int joint = k == 1 ? ankles[foot] : ankles[foot] + 1;
            const vec3 ref = m.position(f, joint);
            double run_max = 0.0;
            int e = f;
            for (; e < c.frame_count && kind[at(e, 2, foot)] == k; ++e)
                run_max = std::max(run_max, static_cast<double>(glm::length(m.position(e, joint) - ref)));
            frames += e - f;
            ++runs;
            sum += run_max;
            worst = std::max(worst, run_max);
            f = e;
        }
    if (report) {
        report->runs = runs;
        report->frames = frames;
        report->max_drift_m = worst;
        report->mean_drift_m = runs > 0 ? sum / runs : 0.0;
    }
    return worst;
}

// The height of the ground the puppet's feet stand on: the median, over the
// foot-frames the source plants, of the planted point's height (kind 1: the sole
// under the ankle, the rest pose's ankle height below it in the foot's frame;
// kind 2: the ball, the toe joint). Without contacts, the 2nd percentile over
// frames of the lowest foot joint, as the source's floor is found.
float planted_ground(const Clip& c, const std::vector<unsigned char>& kind) {
    std::vector<quat> rest_rot;
    std::vector<vec3> rest_pos;
    rest_model_pose(c.skeleton, rest_rot, rest_pos);
    const ModelFrames m = model_frames(c);
    std::vector<float> heights;
    for (int f = 0; f < c.frame_count; ++f)
        for (int foot = 0; foot < 2; ++foot) {
            const int ankle = kFootRole[foot], toe = ankle + 1;
            const size_t a = static_cast<size_t>(ankle), t = static_cast<size_t>(toe);
            const int k = kind[at(f, 2, foot)];
            if (k == 0) continue;
            // The sole under the ankle, carried from the rest pose by the foot's rotation since rest.
            const vec3 rest_sole = quat_rotate(quat_conjugate(rest_rot[a]), vec3(0.0f, rest_pos[t].y - rest_pos[a].y, 0.0f));
            heights.push_back(k == 1 ? (m.position(f, ankle) + quat_rotate(m.rotation(f, ankle), rest_sole)).y : m.position(f, toe).y);
        }
    if (heights.empty()) {
        for (int f = 0; f < c.frame_count; ++f) {
            float low = m.position(f, role::foot_l).y;
            for (int p : {role::foot_l, role::toe_l, role::foot_r, role::toe_r}) low = std::min(low, m.position(f, p).y);
            heights.push_back(low);
        }
        std::sort(heights.begin(), heights.end());
        return heights[heights.size() / 50];
    }
    const auto mid = heights.begin() + static_cast<std::ptrdiff_t>(heights.size() / 2);
    std::nth_element(heights.begin(), mid, heights.end());
    return *mid;
}

}  // namespace

void fix_contacts(const ModelFrames& source, const HumanoidChains& h, const SourceToPuppet& sp, const RetargetOptions& o,
                  float puppet_leg, RetargetResult& result) {
    Clip& c = result.clip;
    result.contact_kind = detect(source, h, sp, o, puppet_leg, c.frame_rate);
    // The puppet's feet onto the ground: its legs need not have the source's
    // proportions, so at the source's scaled hip height its planted feet float or
    // sink (CMU subject 16 on the default puppet: 6-8 cm above the ground).
    // The pelvis moves by that, before the contacts pin the feet.
    result.ground_shift_m = planted_ground(c, result.contact_kind);
    for (int f = 0; f < c.frame_count; ++f) c.translations[at(f, c.joint_count(), 0)].y -= static_cast<float>(result.ground_shift_m);
    result.contacts.max_drift_before_ik_m = measure_drift(c, result.contact_kind, nullptr);
    if (o.fix_contacts) pin_feet(c, result.contact_kind, o, result.contacts);
    measure_drift(c, result.contact_kind, &result.contacts);
}

}  // namespace marionette::retarget::detail
