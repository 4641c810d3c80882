#include "runtime/anim/skeleton.hpp"

#include <map>

namespace marionette {

int Skeleton::find(std::string_view name) const {
    for (int i = 0; i < joint_count(); ++i)
        if (joint_names[static_cast<size_t>(i)] == name) return i;
    return -1;
}

Outcome validate_skeleton(const Skeleton& s) {
    const size_t n = s.parents.size();
    if (s.joint_names.size() != n || s.rest_offsets.size() != n)
        return Outcome::failure("joint name, parent and offset arrays differ in size");
    if (n == 0) return Outcome::failure("skeleton has no joints");
    std::map<std::string_view, size_t> seen;
    for (size_t i = 0; i < n; ++i) {
        if (s.parents[i] != kNoParent && (s.parents[i] < 0 || static_cast<size_t>(s.parents[i]) >= i))
            return Outcome::failure("joint '" + s.joint_names[i] + "' has parent index " +
                                    std::to_string(s.parents[i]) + ", which is not an earlier joint");
        if (s.joint_names[i].empty()) return Outcome::failure("joint " + std::to_string(i) + " has an empty name");
        auto [it, inserted] = seen.emplace(s.joint_names[i], i);
        if (!inserted) return Outcome::failure("duplicate joint name '" + s.joint_names[i] + "'");
    }
    if (s.end_site_parents.size() != s.end_site_offsets.size())
        return Outcome::failure("end site parent and offset arrays differ in size");
    for (int p : s.end_site_parents)
        if (p < 0 || static_cast<size_t>(p) >= n) return Outcome::failure("end site has an invalid parent index");
    return Outcome::success();
}

Pose rest_pose(const Skeleton& s) {
    Pose pose;
    pose.local_rotations.assign(s.parents.size(), quat_identity());
    pose.local_translations = s.rest_offsets;
    return pose;
}

bool LocalToModelJob::validate() const {
    const size_t n = parents.size();
    return input.rotations.size() == n && input.translations.size() == n && output.rotations.size() >= n &&
           output.positions.size() >= n && parents_in_topological_order(parents);
}

bool LocalToModelJob::run_reference() const {
    if (!validate()) return false;
    const size_t n = parents.size();
    for (size_t i = 0; i < n; ++i) {
        const int p = parents[i];
        if (p == kNoParent) {
            output.rotations[i] = input.rotations[i];
            output.positions[i] = input.translations[i];
        } else {
            const quat parent_rotation = output.rotations[static_cast<size_t>(p)];
            output.rotations[i] = quat_mul(parent_rotation, input.rotations[i]);
            output.positions[i] =
                output.positions[static_cast<size_t>(p)] + quat_rotate(parent_rotation, input.translations[i]);
        }
    }
    return true;
}

namespace {

// Four floats, one per joint. Plain IEEE lane arithmetic (FP contraction is off
// project-wide, so no lane op fuses).
using f4 = float __attribute__((vector_size(16)));

struct QuatLanes {
    f4 w, x, y, z;
};
struct VecLanes {
    f4 x, y, z;
};

QuatLanes load_quats(std::span<const quat> q, const int* idx) {
    const quat& a = q[static_cast<size_t>(idx[0])];
    const quat& b = q[static_cast<size_t>(idx[1])];
    const quat& c = q[static_cast<size_t>(idx[2])];
    const quat& d = q[static_cast<size_t>(idx[3])];
    return {f4{a.w, b.w, c.w, d.w}, f4{a.x, b.x, c.x, d.x}, f4{a.y, b.y, c.y, d.y}, f4{a.z, b.z, c.z, d.z}};
}

VecLanes load_vecs(std::span<const vec3> v, const int* idx) {
    const vec3& a = v[static_cast<size_t>(idx[0])];
    const vec3& b = v[static_cast<size_t>(idx[1])];
    const vec3& c = v[static_cast<size_t>(idx[2])];
    const vec3& d = v[static_cast<size_t>(idx[3])];
    return {f4{a.x, b.x, c.x, d.x}, f4{a.y, b.y, c.y, d.y}, f4{a.z, b.z, c.z, d.z}};
}

// Joints joint[0..4) (all of one depth, so none is another's parent): lane k
// computes exactly what run_reference() computes for joint[k], operation for
// operation (quat_mul, then quat_rotate, then the parent's position plus it).
void solve_four(const LocalToModelJob& job, const int* joint, const int* parent, int count) {
    std::span<const quat> model_r(job.output.rotations.data(), job.output.rotations.size());
    std::span<const vec3> model_p(job.output.positions.data(), job.output.positions.size());
    const QuatLanes a = load_quats(model_r, parent);
    const QuatLanes b = load_quats(job.input.rotations, joint);
    const VecLanes v = load_vecs(job.input.translations, joint);
    const VecLanes base = load_vecs(model_p, parent);
    // quat_mul(a, b)
    const f4 rw = a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z;
    const f4 rx = a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y;
    const f4 ry = a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x;
    const f4 rz = a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w;
    // quat_rotate(a, v): t = 2 (u × v); v + w t + u × t
    const f4 two = {2.0f, 2.0f, 2.0f, 2.0f};
    const f4 tx = two * (a.y * v.z - a.z * v.y);
    const f4 ty = two * (a.z * v.x - a.x * v.z);
    const f4 tz = two * (a.x * v.y - a.y * v.x);
    const f4 px = base.x + (v.x + a.w * tx + (a.y * tz - a.z * ty));
    const f4 py = base.y + (v.y + a.w * ty + (a.z * tx - a.x * tz));
    const f4 pz = base.z + (v.z + a.w * tz + (a.x * ty - a.y * tx));
    for (int k = 0; k < count; ++k) {
        const size_t j = static_cast<size_t>(joint[k]);
        job.output.rotations[j] = quat(rw[k], rx[k], ry[k], rz[k]);
        job.output.positions[j] = vec3(px[k], py[k], pz[k]);
    }
}

}  // namespace

bool LocalToModelJob::run() const {
    const size_t n = parents.size();
    if (n > kLocalToModelBatchedJoints) return run_reference();
    if (!validate()) return false;
    // Depth of every joint, then the joints in order of depth (a stable counting
    // sort: within a level, joint order).
    int depth[kLocalToModelBatchedJoints];
    int first[kLocalToModelBatchedJoints + 2] = {};
    int order[kLocalToModelBatchedJoints];
    for (size_t i = 0; i < n; ++i) {
        const int p = parents[i];
        depth[i] = p == kNoParent ? 0 : depth[static_cast<size_t>(p)] + 1;
        ++first[depth[i] + 1];
    }
    for (size_t d = 1; d <= n; ++d) first[d] += first[d - 1];
    int fill[kLocalToModelBatchedJoints + 1];
    for (size_t d = 0; d <= n; ++d) fill[d] = first[d];
    for (size_t i = 0; i < n; ++i) order[fill[depth[i]]++] = static_cast<int>(i);
    // Roots (depth 0) copy their locals.
    for (int k = 0; k < first[1]; ++k) {
        const size_t i = static_cast<size_t>(order[k]);
        output.rotations[i] = input.rotations[i];
        output.positions[i] = input.translations[i];
    }
    for (size_t d = 1; d < n && first[d] < first[d + 1]; ++d) {
        for (int k = first[d]; k < first[d + 1]; k += 4) {
            const int count = first[d + 1] - k < 4 ? first[d + 1] - k : 4;
            int joint[4], parent[4];
            for (int l = 0; l < 4; ++l) {
                joint[l] = order[k + (l < count ? l : count - 1)];  // spare lanes repeat the last joint
                parent[l] = parents[static_cast<size_t>(joint[l])];
            }
            solve_four(*this, joint, parent, count);
        }
    }
    return true;
}

}  // namespace marionette
