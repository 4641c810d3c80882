#include "runtime/anim/two_bone_ik.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>

#if defined(__SSE__)
#include <xmmintrin.h>
#elif defined(__aarch64__)
#include <arm_neon.h>
#endif

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

namespace {
// What validate() asks of a job's inputs (the result pointer aside).
bool inputs_valid(const TwoBoneIkJob& j) {
    return j.upper_length > 0.0f && j.lower_length > 0.0f && std::isfinite(j.upper_length) && std::isfinite(j.lower_length) &&
           finite3(j.root) && finite3(j.target) && finite3(j.pole) && j.soft_reach_start > 0.0f && j.soft_reach_start <= 1.0f &&
           j.min_reach_margin >= 0.0f;
}
}  // namespace

bool TwoBoneIkJob::validate() const { return result && inputs_valid(*this); }

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

// The lane kernel. Every scalar float of solve_two_bone_ik is an F4 (one job
// per lane) and every vec3 a V3 of three F4s; the expressions below are the
// scalar ones, term for term, so each lane rounds exactly as the scalar code
// does (-ffp-contract=off project-wide: no FMA). A branch of the scalar code
// computes both sides here and selects per lane; the side a lane does not take
// may divide by zero or take a negative square root, harmlessly (IEEE, no
// traps), and is never selected.
namespace {

using F4 = float __attribute__((vector_size(16)));
using M4 = std::int32_t __attribute__((vector_size(16)));  // a comparison: all ones (true) or zero per lane

F4 splat(float v) { return F4{v, v, v, v}; }

F4 sqrt4(F4 v) {
#if defined(__SSE__)
    return F4(_mm_sqrt_ps(__m128(v)));
#elif defined(__aarch64__)
    return F4(vsqrtq_f32(float32x4_t(v)));
#else
    return F4{std::sqrt(v[0]), std::sqrt(v[1]), std::sqrt(v[2]), std::sqrt(v[3])};
#endif
}

// Per lane: `when` ? a : b (bit for bit).
F4 select(M4 when, F4 a, F4 b) {
    M4 ia, ib;
    std::memcpy(&ia, &a, sizeof ia);
    std::memcpy(&ib, &b, sizeof ib);
    const M4 r = (ia & when) | (ib & ~when);
    F4 out;
    std::memcpy(&out, &r, sizeof out);
    return out;
}

F4 abs4(F4 v) {
    M4 bits;
    std::memcpy(&bits, &v, sizeof bits);
    bits &= M4{0x7fffffff, 0x7fffffff, 0x7fffffff, 0x7fffffff};
    std::memcpy(&v, &bits, sizeof v);
    return v;
}

struct V3 {
    F4 x, y, z;
};
V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V3 operator-(V3 a) { return {-a.x, -a.y, -a.z}; }
V3 operator*(V3 a, F4 s) { return {a.x * s, a.y * s, a.z * s}; }
V3 operator/(V3 a, F4 s) { return {a.x / s, a.y / s, a.z / s}; }
F4 dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
F4 length(V3 v) { return sqrt4(dot(v, v)); }
V3 select(M4 when, V3 a, V3 b) { return {select(when, a.x, b.x), select(when, a.y, b.y), select(when, a.z, b.z)}; }
V3 splat(vec3 v) { return {splat(v.x), splat(v.y), splat(v.z)}; }

struct Q4 {
    F4 w, x, y, z;
};

// any_perpendicular, per lane.
V3 any_perpendicular4(V3 v) {
    const M4 small_x = abs4(v.x) < splat(0.9f);
    const V3 other = select(small_x, splat(vec3(1.0f, 0.0f, 0.0f)), splat(vec3(0.0f, 1.0f, 0.0f)));
    const V3 p = cross(v, other);
    return p / length(p);
}

// quat_normalize, per lane.
Q4 normalize4(Q4 q) {
    const F4 n2 = q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z;
    const F4 inv = splat(1.0f) / sqrt4(n2);
    const Q4 n{q.w * inv, q.x * inv, q.y * inv, q.z * inv};
    const M4 positive = n2 > splat(0.0f);
    return {select(positive, n.w, splat(1.0f)), select(positive, n.x, splat(0.0f)), select(positive, n.y, splat(0.0f)),
            select(positive, n.z, splat(0.0f))};
}

// quat_from_axes, per lane. Each of Shepperd's four cases divides three of six
// numerators by s and puts the quarter of s in the fourth component; each lane
// picks its case's square root argument and three numerators (in component
// order), so three divisions serve all four cases.
Q4 from_axes4(V3 x, V3 y, V3 z) {
    const F4 m00 = x.x, m11 = y.y, m22 = z.z;
    const F4 trace = m00 + m11 + m22;
    const M4 case0 = trace > splat(0.0f);
    const M4 case1 = ~case0 & (m00 > m11) & (m00 > m22);
    const M4 case2 = ~case0 & ~case1 & (m11 > m22);
    const M4 case3 = ~case0 & ~case1 & ~case2;
    const F4 one = splat(1.0f);
    const F4 argument = select(case0, trace + one,
                               select(case1, one + m00 - m11 - m22, select(case2, one + m11 - m00 - m22, one + m22 - m00 - m11)));
    const F4 s = sqrt4(argument) * splat(2.0f);
    const F4 quarter = splat(0.25f) * s;
    const F4 a = y.z - z.y, b = z.x - x.z, c = x.y - y.x;  // the case's w (cases 1-3) or x, y, z (case 0)
    const F4 d = y.x + x.y, e = z.x + x.z, f = z.y + y.z;
    const F4 first = select(case0 | case1, a, select(case2, b, c)) / s;
    const F4 second = select(case0, b, select(case1 | case2, d, e)) / s;
    const F4 third = select(case0, c, select(case1, e, f)) / s;
    return normalize4({select(case0, quarter, first), select(case0, first, select(case1, quarter, second)),
                       select(case0 | case1, second, select(case2, quarter, third)), select(case3, quarter, third)});
}

// Whether any lane's mask is set (a branch around work no lane needs: the
// selected values are the same either way).
bool any(M4 m) { return (m[0] | m[1] | m[2] | m[3]) != 0; }

}  // namespace

void solve_two_bone_ik_lanes(std::span<const TwoBoneIkJob> jobs, std::span<TwoBoneIkResult> results) {
    const std::size_t n = jobs.size() < results.size() ? jobs.size() : results.size();
    if (n == 0) return;
    // Unused lanes repeat the first job, so they hold ordinary numbers.
    F4 a{}, b{}, margin{}, soft_start{}, sign{};
    V3 root{}, target{}, pole_in{};
    for (std::size_t lane = 0; lane < 4; ++lane) {
        const TwoBoneIkJob& j = jobs[lane < n ? lane : 0];
        a[lane] = j.upper_length;
        b[lane] = j.lower_length;
        margin[lane] = j.min_reach_margin;
        soft_start[lane] = j.soft_reach_start;
        sign[lane] = j.hinge_sign < 0.0f ? -1.0f : 1.0f;
        root.x[lane] = j.root.x, root.y[lane] = j.root.y, root.z[lane] = j.root.z;
        target.x[lane] = j.target.x, target.y[lane] = j.target.y, target.z[lane] = j.target.z;
        pole_in.x[lane] = j.pole.x, pole_in.y[lane] = j.pole.y, pole_in.z[lane] = j.pole.z;
    }
    const F4 full = a + b;
    const F4 fold = abs4(a - b) + margin * full;

    const V3 to_target = target - root;
    const F4 distance = length(to_target);
    const F4 pole_length = length(pole_in);
    const V3 pole = select(pole_length > splat(1e-12f), pole_in / pole_length, splat(vec3(0.0f, 0.0f, 1.0f)));
    const M4 has_distance = distance > splat(1e-9f);
    const V3 dir = any(~has_distance) ? select(has_distance, to_target / distance, any_perpendicular4(pole)) : to_target / distance;

    const F4 soft = soft_start * full;
    F4 reach = distance;
    const M4 past_soft = reach > soft;
    if (any(past_soft)) {
        const F4 x = reach - soft;
        const F4 r = full - soft;
        const F4 eased = select(r > splat(0.0f), soft + r * x / (x + r), full);
        reach = select(past_soft, eased, reach);
    }
    reach = select(reach < fold, fold, reach);
    reach = select(reach > full, full, reach);

    V3 bend = pole - dir * dot(pole, dir);
    const F4 bend_length = length(bend);
    const M4 has_bend = bend_length > splat(1e-6f);
    bend = any(~has_bend) ? select(has_bend, bend / bend_length, any_perpendicular4(dir)) : bend / bend_length;

    F4 cos_a = (a * a + reach * reach - b * b) / (splat(2.0f) * a * reach);
    cos_a = select(cos_a > splat(1.0f), splat(1.0f), select(cos_a < splat(-1.0f), splat(-1.0f), cos_a));
    const F4 sin_a = sqrt4(splat(1.0f) - cos_a * cos_a);
    const V3 mid = root + dir * (a * cos_a) + bend * (a * sin_a);
    const V3 end = root + dir * reach;

    V3 hinge = cross(bend, dir);
    hinge = hinge * (sign / length(hinge));
    const V3 upper_y = -((mid - root) / a);
    const V3 lower_y = -((end - mid) / b);
    const Q4 upper = from_axes4(hinge, upper_y, cross(hinge, upper_y));
    const Q4 lower = from_axes4(hinge, lower_y, cross(hinge, lower_y));
    const V3 miss = end - target;
    const M4 reached = dot(miss, miss) <= splat(1e-8f);

    for (std::size_t lane = 0; lane < n; ++lane) {
        TwoBoneIkResult& out = results[lane];
        out.mid = vec3(mid.x[lane], mid.y[lane], mid.z[lane]);
        out.end = vec3(end.x[lane], end.y[lane], end.z[lane]);
        out.hinge_axis = vec3(hinge.x[lane], hinge.y[lane], hinge.z[lane]);
        out.upper_rotation = quat(upper.w[lane], upper.x[lane], upper.y[lane], upper.z[lane]);
        out.lower_rotation = quat(lower.w[lane], lower.x[lane], lower.y[lane], lower.z[lane]);
        out.reach = reach[lane];
        out.reached = reached[lane] != 0;
    }
}

bool TwoBoneIkLanesJob::validate() const {
    if (jobs.empty() || jobs.size() > 4 || results.size() != jobs.size()) return false;
    for (const TwoBoneIkJob& j : jobs)
        if (!inputs_valid(j)) return false;
    return true;
}

bool TwoBoneIkLanesJob::run() const {
    if (!validate()) return false;
    solve_two_bone_ik_lanes(jobs, results);
    return true;
}

}  // namespace marionette
