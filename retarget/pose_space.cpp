#include "retarget/pose_space.hpp"

#include <span>
#include <stdexcept>

namespace marionette::retarget {

namespace {
void fk(const Skeleton& s, std::span<const quat> local_r, std::span<const vec3> local_t, quat* rot, vec3* pos) {
    const size_t n = static_cast<size_t>(s.joint_count());
    const LocalToModelJob job{s.parents, {local_r, local_t}, {std::span<quat>(rot, n), std::span<vec3>(pos, n)}};
    if (!job.run()) throw std::invalid_argument("retarget: a clip whose skeleton is not in topological order");
    for (size_t e = 0; e < s.end_site_parents.size(); ++e) {
        const size_t p = static_cast<size_t>(s.end_site_parents[e]);
        pos[n + e] = pos[p] + quat_rotate(rot[p], s.end_site_offsets[e]);
    }
}
}  // namespace

void rest_model_pose(const Skeleton& s, std::vector<quat>& rotations, std::vector<vec3>& points) {
    const Pose rest = rest_pose(s);
    rotations.assign(static_cast<size_t>(s.joint_count()), quat_identity());
    points.assign(static_cast<size_t>(s.joint_count()) + s.end_site_parents.size(), vec3(0.0f));
    fk(s, rest.local_rotations, rest.local_translations, rotations.data(), points.data());
}

ModelFrames model_frames(const Clip& clip) {
    ModelFrames m;
    m.joints = clip.joint_count();
    m.points = m.joints + static_cast<int>(clip.skeleton.end_site_parents.size());
    m.rotations.resize(static_cast<size_t>(clip.frame_count) * static_cast<size_t>(m.joints));
    m.positions.resize(static_cast<size_t>(clip.frame_count) * static_cast<size_t>(m.points));
    const size_t n = static_cast<size_t>(m.joints);
    for (int f = 0; f < clip.frame_count; ++f)
        fk(clip.skeleton, std::span<const quat>(clip.frame_rotations(f), n), std::span<const vec3>(clip.frame_translations(f), n),
           m.rotations.data() + static_cast<size_t>(f) * n, m.positions.data() + static_cast<size_t>(f) * static_cast<size_t>(m.points));
    return m;
}

}  // namespace marionette::retarget
