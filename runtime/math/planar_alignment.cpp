#include "runtime/math/planar_alignment.hpp"

#include <cmath>

namespace marionette {

vec3 apply_planar(const PlanarTransform& t, vec3 p) {
    double s = 0.0, c = 0.0;
    det::sin_cos(t.angle, s, c);
    return vec3(static_cast<float>(c * p.x + s * p.z + t.dx), p.y, static_cast<float>(-s * p.x + c * p.z + t.dz));
}

quat planar_rotation(const PlanarTransform& t) { return quat_axis_angle(vec3(0.0f, 1.0f, 0.0f), t.angle); }

PlanarTransform compose_planar(const PlanarTransform& first, const PlanarTransform& second) {
    double s = 0.0, c = 0.0;
    det::sin_cos(first.angle, s, c);
    PlanarTransform out;
    out.angle = det::wrap_angle(first.angle + second.angle);
    out.dx = c * second.dx + s * second.dz + first.dx;
    out.dz = -s * second.dx + c * second.dz + first.dz;
    return out;
}

void accumulate_planar_sums(PlanarCrossSums& sums, vec3 a, vec3 b, double w) {
    const double ax = a.x, az = a.z, bx = b.x, bz = b.z;
    sums.weight += w;
    sums.ax += w * ax;
    sums.az += w * az;
    sums.bx += w * bx;
    sums.bz += w * bz;
    sums.dot += w * (ax * bx + az * bz);
    sums.cross += w * (ax * bz - az * bx);
}

PlanarTransform align_from_sums(const PlanarCrossSums& s) {
    PlanarTransform t;
    if (!(s.weight > 0.0)) return t;
    const double dot = s.dot - (s.ax * s.bx + s.az * s.bz) / s.weight;
    const double cross = s.cross - (s.ax * s.bz - s.az * s.bx) / s.weight;
    t.angle = (dot == 0.0 && cross == 0.0) ? 0.0 : det::atan2(cross, dot);
    double sn = 0.0, c = 0.0;
    det::sin_cos(t.angle, sn, c);
    t.dx = (s.ax - (c * s.bx + sn * s.bz)) / s.weight;
    t.dz = (s.az - (-sn * s.bx + c * s.bz)) / s.weight;
    return t;
}

PlanarTransform align_point_clouds(std::span<const vec3> a, std::span<const vec3> b, std::span<const float> weights) {
    PlanarCrossSums sums;
    for (size_t i = 0; i < a.size() && i < b.size() && i < weights.size(); ++i)
        accumulate_planar_sums(sums, a[i], b[i], weights[i]);
    return align_from_sums(sums);
}

double planar_cloud_distance(std::span<const vec3> a, std::span<const vec3> b, std::span<const float> weights,
                             const PlanarTransform& t) {
    double s = 0.0, c = 0.0;
    det::sin_cos(t.angle, s, c);
    double sum = 0.0;
    for (size_t i = 0; i < a.size() && i < b.size() && i < weights.size(); ++i) {
        const double x = c * b[i].x + s * b[i].z + t.dx;
        const double z = -s * b[i].x + c * b[i].z + t.dz;
        const double ex = a[i].x - x, ey = static_cast<double>(a[i].y) - b[i].y, ez = a[i].z - z;
        sum += weights[i] * (ex * ex + ey * ey + ez * ez);
    }
    return sum;
}

}  // namespace marionette
