#pragma once
// Small direction helpers shared by the puppet retargeter (retarget.cpp,
// contacts.cpp) and the fill database's skeleton-to-skeleton transfer
// (graph_builder/fill_retarget.cpp): one definition of each.
#include <cmath>
#include <cstddef>
#include <vector>

#include "retarget/humanoid.hpp"

namespace marionette::retarget {

// `v` normalised into `out`; false (out untouched) for a (near-)zero vector.
inline bool unit(vec3 v, vec3& out) {
    const float l = std::sqrt(glm::dot(v, v));
    if (!(l > 1e-8f)) return false;
    out = v / l;
    return true;
}

// Rotation about +Y taking the horizontal part of `a` onto that of `b`
// (identity when either has no horizontal part).
inline quat yaw_from_to(vec3 a, vec3 b) {
    vec3 ua, ub;
    if (!unit(vec3(a.x, 0.0f, a.z), ua) || !unit(vec3(b.x, 0.0f, b.z), ub)) return quat_identity();
    const float d = glm::dot(ua, ub);
    if (d < -0.99999f) return quat_wxyz(0.0f, 0.0f, 1.0f, 0.0f);
    const vec3 c = glm::cross(ua, ub);
    return quat_normalize(quat_wxyz(1.0f + d, c.x, c.y, c.z));
}

// A source point (a joint, or a point between two) of one frame's positions.
inline vec3 point_of(const std::vector<vec3>& p, SourcePoint s) {
    return lerp(p[static_cast<std::size_t>(s.a)], p[static_cast<std::size_t>(s.b)], s.t);
}

}  // namespace marionette::retarget
