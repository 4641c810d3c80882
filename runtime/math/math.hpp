#pragma once
// GLM configuration shared by every target, plus the few quaternion helpers the
// runtime needs. Everything here is built from +,-,*,/ and sqrt (correctly
// rounded by IEEE 754) or from det_math, so results are identical on every
// platform and optimisation level (with FP contraction off).
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "runtime/math/det_math.hpp"

namespace marionette {

using glm::quat;
using glm::vec2;
using glm::vec3;

// GLM's quat constructor takes (w, x, y, z); spelled out here so call sites
// never have to remember which.
inline quat quat_wxyz(float w, float x, float y, float z) { return quat(w, x, y, z); }
inline quat quat_identity() { return quat(1.0f, 0.0f, 0.0f, 0.0f); }

// Rotation of `radians` about a unit axis, using the owned sin/cos.
inline quat quat_axis_angle(vec3 unit_axis, double radians) {
    double s = 0.0;
    double c = 0.0;
    det::sin_cos(radians * 0.5, s, c);
    return quat(static_cast<float>(c), static_cast<float>(unit_axis.x * s),
                static_cast<float>(unit_axis.y * s), static_cast<float>(unit_axis.z * s));
}

inline quat quat_normalize(quat q) {
    const float n2 = q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z;
    if (!(n2 > 0.0f)) return quat_identity();
    const float inv = 1.0f / std::sqrt(n2);
    return quat(q.w * inv, q.x * inv, q.y * inv, q.z * inv);
}

inline float quat_dot(quat a, quat b) { return a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z; }

// Hamilton product a*b (apply b, then a), written out so no library code with
// possible FMA contraction is involved.
inline quat quat_mul(quat a, quat b) {
    return quat(a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
                a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
                a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
                a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w);
}

inline quat quat_conjugate(quat q) { return quat(q.w, -q.x, -q.y, -q.z); }

inline vec3 quat_rotate(quat q, vec3 v) {
    // v' = v + 2w(u×v) + 2u×(u×v), u = vector part
    const vec3 u(q.x, q.y, q.z);
    const vec3 t = 2.0f * vec3(u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x);
    return v + q.w * t + vec3(u.y * t.z - u.z * t.y, u.z * t.x - u.x * t.z, u.x * t.y - u.y * t.x);
}

// Shortest-arc spherical interpolation with the owned acos/sin; falls back to
// normalised lerp when the quaternions are nearly equal.
inline quat quat_slerp(quat a, quat b, float t) {
    float d = quat_dot(a, b);
    if (d < 0.0f) {
        b = quat(-b.w, -b.x, -b.y, -b.z);
        d = -d;
    }
    float wa = 1.0f - t;
    float wb = t;
    if (d < 0.9995f) {
        const double theta = det::acos(static_cast<double>(d));
        const double inv_sin = 1.0 / det::sin(theta);
        wa = static_cast<float>(det::sin((1.0 - t) * theta) * inv_sin);
        wb = static_cast<float>(det::sin(t * theta) * inv_sin);
    }
    return quat_normalize(quat(wa * a.w + wb * b.w, wa * a.x + wb * b.x, wa * a.y + wb * b.y,
                               wa * a.z + wb * b.z));
}

inline vec3 lerp(vec3 a, vec3 b, float t) { return a + (b - a) * t; }

// Angle in radians between two rotations (0..pi), computed in double from the
// relative rotation's vector part, which stays accurate near zero.
inline double quat_angle_between(quat a, quat b) {
    const quat r = quat_mul(quat_conjugate(a), b);
    const double vx = r.x, vy = r.y, vz = r.z, w = r.w;
    const double vn = std::sqrt(vx * vx + vy * vy + vz * vz);
    return 2.0 * det::atan2(vn, w < 0 ? -w : w);
}

}  // namespace marionette
