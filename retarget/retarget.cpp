#include "retarget/retarget.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "retarget/retarget_detail.hpp"
#include "runtime/anim/two_bone_ik.hpp"
#include "runtime/errors/import_error.hpp"

namespace marionette::retarget {

using detail::at;

namespace {

const vec3 kUp(0.0f, 1.0f, 0.0f);

using detail::point_of;  // a point of a ModelFrames frame
using retarget::point_of;  // a point of one frame's positions (retarget/directions.hpp)

// A Z-up source turned Y-up as a whole: every offset turned, every local
// rotation conjugated, the roots' translations turned.
void make_y_up(Clip& clip) {
    const quat c = quat_wxyz(0.70710678f, -0.70710678f, 0.0f, 0.0f);  // −90° about X: +Z → +Y
    const quat ci = quat_conjugate(c);
    Skeleton& s = clip.skeleton;
    for (vec3& o : s.rest_offsets) o = quat_rotate(c, o);
    for (vec3& o : s.end_site_offsets) o = quat_rotate(c, o);
    for (int f = 0; f < clip.frame_count; ++f)
        for (int j = 0; j < clip.joint_count(); ++j) {
            const size_t i = at(f, clip.joint_count(), j);
            clip.rotations[i] = quat_normalize(quat_mul(quat_mul(c, clip.rotations[i]), ci));
            clip.translations[i] = quat_rotate(c, clip.translations[i]);
        }
}

int end_site_of(const Skeleton& s, int j) {
    for (size_t e = 0; e < s.end_site_parents.size(); ++e)
        if (s.end_site_parents[e] == j) return s.joint_count() + static_cast<int>(e);
    return -1;
}

// Everything the per-frame transfer needs, fixed over the clip.
struct Transfer {
    quat yaw = quat_identity();              // source rest facing → +Z
    float scale = 1.0f;                      // source units → metres
    float floor = 0.0f;                      // source ground height
    std::array<int, kRoleCount> puppet_end{};  // puppet point each bone ends at
    std::array<vec3, kRoleCount> rest_dir{};   // source rest direction, yawed
    std::array<quat, kRoleCount> align{};      // puppet rest direction → source rest direction (then puppet rest frame)
    std::array<quat, kRoleCount> inv_rest{};   // inverse source rest world rotation of the driving joint
};

Transfer make_transfer(const Clip& src, const Skeleton& puppet, const HumanoidChains& h, float& puppet_leg) {
    Transfer t;
    std::vector<quat> src_rot, pup_rot;
    std::vector<vec3> src_p, pup_p;
    rest_model_pose(src.skeleton, src_rot, src_p);
    rest_model_pose(puppet, pup_rot, pup_p);
    const vec3 lateral = src_p[static_cast<size_t>(h.joint[role::thigh_l])] - src_p[static_cast<size_t>(h.joint[role::thigh_r])];
    t.yaw = yaw_from_to(glm::cross(vec3(lateral.x, 0.0f, lateral.z), kUp), vec3(0.0f, 0.0f, 1.0f));
    float pup_floor = pup_p[role::toe_l].y;
    for (int toe : {role::toe_l, role::toe_r}) {
        pup_floor = std::min(pup_floor, pup_p[static_cast<size_t>(toe)].y);
        const int e = end_site_of(puppet, toe);
        if (e >= 0) pup_floor = std::min(pup_floor, pup_p[static_cast<size_t>(e)].y);
    }
    puppet_leg = 0.5f * (pup_p[role::thigh_l].y + pup_p[role::thigh_r].y) - pup_floor;
    t.scale = puppet_leg / h.source_leg_length;
    t.floor = h.source_floor;
    for (int r = 0; r < kRoleCount; ++r) {
        const size_t u = static_cast<size_t>(r);
        const int child = child_role(r);
        t.puppet_end[u] = child >= 0 ? child : end_site_of(puppet, r);
        if (t.puppet_end[u] < 0) throw std::invalid_argument("retarget: puppet joint '" + puppet.joint_names[u] + "' has no end site");
        vec3 dp(0.0f, 1.0f, 0.0f), dr(0.0f, 1.0f, 0.0f);
        if (!unit(pup_p[static_cast<size_t>(t.puppet_end[u])] - pup_p[u], dp))
            throw std::invalid_argument("retarget: puppet bone '" + puppet.joint_names[u] + "' has no length");
        const bool has_dir = unit(quat_rotate(t.yaw, point_of(src_p, h.to[u]) - point_of(src_p, h.from[u])), dr);
        if (!has_dir) dr = dp;
        t.rest_dir[u] = dr;
        t.align[u] = quat_mul(quat_from_to(dp, dr), pup_rot[u]);
        t.inv_rest[u] = quat_conjugate(src_rot[static_cast<size_t>(h.joint[u])]);
    }
    return t;
}

// Direction transfer: the puppet's local rotations and root path for every
// frame, and the source's bone directions (world, yawed) for the agreement.
void transfer_frames(const ModelFrames& m, const HumanoidChains& h, const Transfer& t, const Skeleton& puppet, Clip& out,
                     std::vector<vec3>& src_dirs) {
    const int n = kRoleCount;
    src_dirs.assign(static_cast<size_t>(out.frame_count) * n, vec3(0.0f));
    const quat yaw_inv = quat_conjugate(t.yaw);
    std::array<quat, kRoleCount> world{};
    for (int f = 0; f < out.frame_count; ++f) {
        for (int r = 0; r < n; ++r) {
            const size_t u = static_cast<size_t>(r);
            const quat delta = quat_mul(quat_mul(t.yaw, quat_mul(m.rotation(f, h.joint[u]), t.inv_rest[u])), yaw_inv);
            quat w = quat_mul(delta, t.align[u]);
            const vec3 now = quat_rotate(delta, t.rest_dir[u]);
            vec3 target;
            if (unit(quat_rotate(t.yaw, point_of(m, f, h.to[u]) - point_of(m, f, h.from[u])), target))
                w = quat_mul(quat_from_to(now, target), w);
            else
                target = now;
            src_dirs[at(f, n, r)] = target;
            world[u] = quat_normalize(w);
            const int p = puppet.parents[u];
            out.rotations[at(f, n, r)] =
                p == kNoParent ? world[u] : quat_normalize(quat_mul(quat_conjugate(world[static_cast<size_t>(p)]), world[u]));
            out.translations[at(f, n, r)] = puppet.rest_offsets[u];
        }
        // The pelvis goes where the hips' midpoint puts it: the puppet's hips on the
        // source's (scaled), whatever the source root's height above them.
        const vec3 hips = 0.5f * (m.position(f, h.joint[role::thigh_l]) + m.position(f, h.joint[role::thigh_r]));
        const vec3 hip_offset = 0.5f * (puppet.rest_offsets[role::thigh_l] + puppet.rest_offsets[role::thigh_r]);
        out.translations[at(f, n, 0)] =
            t.scale * quat_rotate(t.yaw, hips - vec3(0.0f, t.floor, 0.0f)) - quat_rotate(world[role::pelvis], hip_offset);
    }
}

// The ground under the motion: per frame the lowest foot point, and of those
// the 2nd percentile, so a few glitched frames do not sink the ground.
float motion_floor(const ModelFrames& m, const HumanoidChains& h) {
    const int frames = static_cast<int>(m.positions.size() / static_cast<size_t>(m.points));
    std::vector<float> lowest;
    for (int f = 0; f < frames; ++f) {
        float low = m.position(f, h.joint[role::foot_l]).y;
        for (int r : {role::foot_l, role::toe_l, role::foot_r, role::toe_r}) {
            low = std::min(low, point_of(m, f, h.from[static_cast<size_t>(r)]).y);
            low = std::min(low, point_of(m, f, h.to[static_cast<size_t>(r)]).y);
        }
        lowest.push_back(low);
    }
    std::sort(lowest.begin(), lowest.end());
    return lowest[lowest.size() / 50];
}

void measure_agreement(const Clip& out, const Transfer& t, const HumanoidChains& h, const Skeleton& src,
                       const std::vector<vec3>& src_dirs, std::vector<BoneAgreement>& bones) {
    const ModelFrames m = model_frames(out);
    bones.clear();
    for (int r = 0; r < kRoleCount; ++r) {
        BoneAgreement b;
        b.puppet_joint = out.skeleton.joint_names[static_cast<size_t>(r)];
        b.source_joint = src.joint_names[static_cast<size_t>(h.joint[static_cast<size_t>(r)])];
        b.min_cos = 1.0;
        double sum = 0.0;
        for (int f = 0; f < out.frame_count; ++f) {
            vec3 d;
            if (!unit(m.position(f, t.puppet_end[static_cast<size_t>(r)]) - m.position(f, r), d)) continue;
            const double c = static_cast<double>(glm::dot(d, src_dirs[at(f, kRoleCount, r)]));
            sum += c;
            b.min_cos = std::min(b.min_cos, c);
        }
        b.mean_cos = out.frame_count > 0 ? sum / out.frame_count : 1.0;
        bones.push_back(b);
    }
}

}  // namespace

bool is_puppet_skeleton(const Skeleton& s, const Skeleton& puppet) {
    return s.joint_names == puppet.joint_names && s.parents == puppet.parents;
}

RetargetResult retarget_clip(const Clip& source, const Skeleton& puppet, const std::string& file, const RetargetOptions& o) {
    if (puppet.joint_count() != kRoleCount)
        throw std::invalid_argument("retarget: the target skeleton is not the puppet's (" + std::to_string(puppet.joint_count()) + " joints)");
    Clip src = source;
    if (o.map && o.map->up == "z") make_y_up(src);
    if (src.frame_count < 1) throw ImportError(file, 0, "no frames to retarget");
    // The puppet's spine joints along its pelvis → chest path.
    const float s1 = glm::length(puppet.rest_offsets[role::spine_01]), s2 = glm::length(puppet.rest_offsets[role::spine_02]),
                s3 = glm::length(puppet.rest_offsets[role::spine_03]);
    const float total = std::max(s1 + s2 + s3, 1e-6f);
    RetargetResult result;
    result.chains = detect_humanoid(src, file, o.map, {s1 / total, (s1 + s2) / total});
    const HumanoidChains& h = result.chains;
    float puppet_leg = 0.0f;
    const Transfer t = make_transfer(src, puppet, h, puppet_leg);
    result.scale = t.scale;
    Clip& out = result.clip;
    out.name = source.name;
    out.skeleton = puppet;
    out.frame_rate = source.frame_rate;
    out.frame_count = src.frame_count;
    out.rotations.resize(static_cast<size_t>(out.frame_count) * kRoleCount);
    out.translations.resize(out.rotations.size());
    out.animated_translation.assign(kRoleCount, false);
    out.animated_translation[0] = true;
    out.length_unit = 1.0;
    const ModelFrames m = model_frames(src);
    // The ground under the motion: the lowest foot point over the clip (the rest
    // pose may stand anywhere, as ASF's root at the origin does).
    Transfer tm = t;
    tm.floor = motion_floor(m, h);
    std::vector<vec3> src_dirs;
    transfer_frames(m, h, tm, puppet, out, src_dirs);
    detail::fix_contacts(m, h, detail::SourceToPuppet{tm.yaw, tm.scale, tm.floor}, o, puppet_leg, result);
    measure_agreement(out, tm, h, src.skeleton, src_dirs, result.bones);
    return result;
}

}  // namespace marionette::retarget
