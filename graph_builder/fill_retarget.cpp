#include "graph_builder/fill_retarget.hpp"

#include <array>
#include <cmath>
#include <vector>

#include "retarget/directions.hpp"
#include "retarget/humanoid.hpp"
#include "retarget/pose_space.hpp"
#include "runtime/anim/two_bone_ik.hpp"
#include "runtime/errors/import_error.hpp"

namespace marionette::offline {

namespace {

using retarget::HumanoidChains;
using retarget::kRoleCount;
using retarget::point_of;
using retarget::SourcePoint;
using retarget::unit;
using retarget::yaw_from_to;

// The rest facing (horizontal, perpendicular to the hips' line) of a skeleton.
vec3 rest_facing(const std::vector<vec3>& p, const HumanoidChains& h) {
    const vec3 lateral = p[static_cast<size_t>(h.joint[retarget::role::thigh_l])] -
                         p[static_cast<size_t>(h.joint[retarget::role::thigh_r])];
    return glm::cross(vec3(lateral.x, 0.0f, lateral.z), vec3(0.0f, 1.0f, 0.0f));
}

struct Transfer {
    quat yaw = quat_identity();          // source rest facing → target rest facing
    float scale = 1.0f;                  // target units per source unit
    float src_floor = 0.0f, tgt_floor = 0.0f;
    std::vector<int> role_of;            // per target joint: the role driving it, or −1
    std::array<quat, kRoleCount> align{};     // target rest direction → source rest direction, then target rest frame
    std::array<quat, kRoleCount> inv_rest{};  // inverse source rest world rotation of the driving joint
    std::vector<quat> rest_local;        // per target joint: rest rotation relative to its parent (model space)
};

Transfer make_transfer(const Clip& src, const HumanoidChains& hs, const Clip& tgt, const HumanoidChains& ht) {
    Transfer t;
    std::vector<quat> src_rot, tgt_rot;
    std::vector<vec3> src_p, tgt_p;
    retarget::rest_model_pose(src.skeleton, src_rot, src_p);
    retarget::rest_model_pose(tgt.skeleton, tgt_rot, tgt_p);
    t.yaw = yaw_from_to(rest_facing(src_p, hs), rest_facing(tgt_p, ht));
    t.scale = ht.source_leg_length / hs.source_leg_length;
    t.src_floor = hs.source_floor;
    t.tgt_floor = ht.source_floor;
    const int n = tgt.joint_count();
    t.role_of.assign(static_cast<size_t>(n), -1);
    for (int r = 0; r < kRoleCount; ++r) {
        const size_t u = static_cast<size_t>(r);
        const int j = ht.joint[u];
        if (j < 0 || j >= n || t.role_of[static_cast<size_t>(j)] >= 0) continue;  // first role wins a shared joint
        t.role_of[static_cast<size_t>(j)] = r;
        vec3 dt(0.0f, 1.0f, 0.0f), ds(0.0f, 1.0f, 0.0f);
        const bool has_t = unit(point_of(tgt_p, ht.to[u]) - point_of(tgt_p, ht.from[u]), dt);
        const bool has_s = unit(quat_rotate(t.yaw, point_of(src_p, hs.to[u]) - point_of(src_p, hs.from[u])), ds);
        const quat turn = has_t && has_s ? quat_from_to(dt, ds) : quat_identity();
        t.align[u] = quat_mul(turn, tgt_rot[static_cast<size_t>(j)]);
        t.inv_rest[u] = quat_conjugate(src_rot[static_cast<size_t>(hs.joint[u])]);
    }
    t.rest_local.resize(static_cast<size_t>(n));
    for (int j = 0; j < n; ++j) {
        const int p = tgt.skeleton.parents[static_cast<size_t>(j)];
        t.rest_local[static_cast<size_t>(j)] =
            p == kNoParent ? tgt_rot[static_cast<size_t>(j)]
                           : quat_mul(quat_conjugate(tgt_rot[static_cast<size_t>(p)]), tgt_rot[static_cast<size_t>(j)]);
    }
    return t;
}

}  // namespace

Clip retarget_fill_clip(const Clip& source, const std::string& source_file, const Clip& target,
                        const std::string& target_file) {
    const auto chains = [](const Clip& c, const std::string& file, const char* which) {
        try {
            return retarget::detect_humanoid(c, file, nullptr);
        } catch (const ImportError& e) {
            throw ImportError(e.file(), 0, std::string("its skeleton differs from the input's and cannot be retargeted onto it (") +
                                               which + "): " + e.message() +
                                               "; clip fill reads no map file: its database needs skeletons whose humanoid is found without one");
        }
    };
    const HumanoidChains hs = chains(source, source_file, "the database clip");
    const HumanoidChains ht = chains(target, target_file, "the input");
    const Transfer t = make_transfer(source, hs, target, ht);
    const retarget::ModelFrames m = retarget::model_frames(source);
    const Skeleton& s = target.skeleton;
    const int n = s.joint_count();
    Clip out;
    out.name = source.name;
    out.skeleton = s;
    out.frame_rate = source.frame_rate;
    out.frame_count = source.frame_count;
    out.length_unit = target.length_unit;
    out.animated_translation.assign(static_cast<size_t>(n), false);
    out.rotations.resize(static_cast<size_t>(out.frame_count) * static_cast<size_t>(n));
    out.translations.resize(out.rotations.size());
    const quat yaw_inv = quat_conjugate(t.yaw);
    const int src_root = 0;
    std::vector<quat> world(static_cast<size_t>(n));
    for (int f = 0; f < out.frame_count; ++f) {
        for (int j = 0; j < n; ++j) {
            const size_t u = static_cast<size_t>(j);
            const int p = s.parents[u];
            const int r = t.role_of[u];
            if (r >= 0) {
                const size_t ru = static_cast<size_t>(r);
                const quat delta = quat_mul(quat_mul(t.yaw, quat_mul(m.rotation(f, hs.joint[ru]), t.inv_rest[ru])), yaw_inv);
                world[u] = quat_normalize(quat_mul(delta, t.align[ru]));
            } else {
                world[u] = p == kNoParent ? t.rest_local[u] : quat_mul(world[static_cast<size_t>(p)], t.rest_local[u]);
            }
            const size_t i = static_cast<size_t>(f) * static_cast<size_t>(n) + u;
            out.rotations[i] = p == kNoParent ? world[u] : quat_normalize(quat_mul(quat_conjugate(world[static_cast<size_t>(p)]), world[u]));
            out.translations[i] = s.rest_offsets[u];
        }
        // The root follows the source's root, turned, scaled and set on the target's ground.
        const vec3 sp = m.position(f, src_root) - vec3(0.0f, t.src_floor, 0.0f);
        out.translations[static_cast<size_t>(f) * static_cast<size_t>(n)] =
            t.scale * quat_rotate(t.yaw, sp) + vec3(0.0f, t.tgt_floor, 0.0f);
    }
    if (n > 0) out.animated_translation[0] = true;
    if (const Outcome ok = validate_clip(out); !ok.ok()) throw ImportError(source_file, 0, "retargeted clip: " + ok.problem());
    return out;
}

}  // namespace marionette::offline
