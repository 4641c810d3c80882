#include "runtime/anim/two_bone_ik.hpp"

#include <cmath>

namespace marionette {

namespace {
float dot3(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
vec3 cross3(vec3 a, vec3 b) { return vec3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x); }
float length3(vec3 v) { return std::sqrt(dot3(v, v)); }
bool finite3(vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Any unit vector perpendicular to unit `v`.
vec3 any_perpendicular(vec3 v) {
    const vec3 other = std::fabs(v.x) < 0.9f ? vec3(1.0f, 0.0f, 0.0f) : vec3(0.0f, 1.0f, 0.0f);
    const vec3 p = cross3(v, other);
    return p / length3(p);
}
}  // namespace

bool TwoBoneIkJob::validate() const {
    return result && upper_length > 0.0f && lower_length > 0.0f && std::isfinite(upper_length) && std::isfinite(lower_length) &&
           finite3(root) && finite3(target) && finite3(pole) && soft_reach_start > 0.0f && soft_reach_start <= 1.0f &&
           min_reach_margin >= 0.0f;
}

quat quat_from_axes(vec3 x, vec3 y, vec3 z) {
    // Matrix m[row][col] with columns x, y, z.
    const float m00 = x.x, m11 = y.y, m22 = z.z;
    const float trace = m00 + m11 + m22;
    quat q;
    if (trace > 0.0f) {
        const float s = std::sqrt(trace + 1.0f) * 2.0f;
        q = quat(0.25f * s, (y.z - z.y) / s, (z.x - x.z) / s, (x.y - y.x) / s);
    } else if (m00 > m11 && m00 > m22) {
        const float s = std::sqrt(1.0f + m00 - m11 - m22) * 2.0f;
        q = quat((y.z - z.y) / s, 0.25f * s, (y.x + x.y) / s, (z.x + x.z) / s);
    } else if (m11 > m22) {
        const float s = std::sqrt(1.0f + m11 - m00 - m22) * 2.0f;
        q = quat((z.x - x.z) / s, (y.x + x.y) / s, 0.25f * s, (z.y + y.z) / s);
    } else {
        const float s = std::sqrt(1.0f + m22 - m00 - m11) * 2.0f;
        q = quat((x.y - y.x) / s, (z.x + x.z) / s, (z.y + y.z) / s, 0.25f * s);
    }
    return quat_normalize(q);
}

quat quat_from_to(vec3 from, vec3 to) {
    const float d = dot3(from, to);
    if (d < -0.999999f) {
        const vec3 axis = any_perpendicular(from);
        return quat(0.0f, axis.x, axis.y, axis.z);
    }
    const vec3 c = cross3(from, to);
    return quat_normalize(quat(1.0f + d, c.x, c.y, c.z));
}

TwoBoneIkResult solve_two_bone_ik(const TwoBoneIkJob& in) {
    TwoBoneIkResult out;
    const float a = in.upper_length;
    const float b = in.lower_length;
    const float full = a + b;
    const float fold = std::fabs(a - b) + in.min_reach_margin * full;

    // Direction root → target; a target on the root borrows the direction
    // opposite the pole's perpendicular, i.e. the limb hangs "down" from the pole.
    const vec3 to_target = in.target - in.root;
    const float distance = length3(to_target);
    vec3 pole = in.pole;
    const float pole_length = length3(pole);
    pole = pole_length > 1e-12f ? pole / pole_length : vec3(0.0f, 0.0f, 1.0f);
    vec3 dir;
    if (distance > 1e-9f) {
        dir = to_target / distance;
    } else {
        dir = any_perpendicular(pole);
    }

    // Soft reach: d' = s + r·x/(x + r) for x = d − s beyond the soft start s, with
    // r = full − s. Continuous in value and slope, never reaches `full`.
    const float soft = in.soft_reach_start * full;
    float reach = distance;
    if (reach > soft) {
        const float x = reach - soft;
        const float r = full - soft;
        reach = r > 0.0f ? soft + r * x / (x + r) : full;
    }
    if (reach < fold) reach = fold;
    if (reach > full) reach = full;

    // Bend direction: the pole made perpendicular to dir (Gram–Schmidt); when the
    // pole is parallel to the limb, any perpendicular keeps the solve defined.
    vec3 bend = pole - dir * dot3(pole, dir);
    const float bend_length = length3(bend);
    bend = bend_length > 1e-6f ? bend / bend_length : any_perpendicular(dir);

    // Law of cosines at the root: cos A = (a² + d² − b²) / (2 a d); sin A from
    // cos A (the half-plane is fixed by the pole, so sin A ≥ 0).
    float cos_a = (a * a + reach * reach - b * b) / (2.0f * a * reach);
    cos_a = cos_a > 1.0f ? 1.0f : (cos_a < -1.0f ? -1.0f : cos_a);
    const float sin_a = std::sqrt(1.0f - cos_a * cos_a);
    out.mid = in.root + dir * (a * cos_a) + bend * (a * sin_a);
    out.end = in.root + dir * reach;
    out.reach = reach;

    // Frames: −Y along each bone, X the hinge axis (±bend × dir puts +Z toward or
    // away from the pole for a straight limb), Z = X × Y.
    vec3 hinge = cross3(bend, dir);
    hinge = hinge * ((in.hinge_sign < 0.0f ? -1.0f : 1.0f) / length3(hinge));
    out.hinge_axis = hinge;
    const vec3 upper_bone = (out.mid - in.root) / a;
    const vec3 lower_bone = (out.end - out.mid) / b;
    const vec3 upper_y = -upper_bone;
    const vec3 lower_y = -lower_bone;
    out.upper_rotation = quat_from_axes(hinge, upper_y, cross3(hinge, upper_y));
    out.lower_rotation = quat_from_axes(hinge, lower_y, cross3(hinge, lower_y));
    const vec3 miss = out.end - in.target;
    out.reached = dot3(miss, miss) <= 1e-8f;
    return out;
}

bool TwoBoneIkJob::run() const {
    if (!validate()) return false;
    *result = solve_two_bone_ik(*this);
    return true;
}

}  // namespace marionette
