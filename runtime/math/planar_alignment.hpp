#pragma once
// Kovar–Gleicher–Pighin's optimal rigid 2D alignment of two corresponding point
// clouds: the rotation about the vertical (+Y) axis and the translation on the
// ground plane that bring cloud B closest to cloud A in the weighted least-squares
// sense, in closed form. The motion graph uses it to compare windows of frames
// (distance) and to place the clip it transitions to (transition alignment).
#include <span>

#include "runtime/math/math.hpp"

namespace marionette {

// p ↦ R_y(angle)·p + (dx, 0, dz). R_y is the right-handed rotation about +Y
// (x' = cos·x + sin·z, z' = −sin·x + cos·z), the same as quat_axis_angle(+Y, angle).
struct PlanarTransform {
    double angle = 0.0;  // radians
    double dx = 0.0;
    double dz = 0.0;
};

vec3 apply_planar(const PlanarTransform& t, vec3 p);
quat planar_rotation(const PlanarTransform& t);
// first ∘ second: apply `second`, then `first`.
PlanarTransform compose_planar(const PlanarTransform& first, const PlanarTransform& second);

// The weighted sums the closed form needs (a from cloud A, b from cloud B):
// total weight, weighted coordinate sums, Σw(ax·bx + az·bz) and Σw(ax·bz − az·bx).
struct PlanarCrossSums {
    double weight = 0.0;
    double ax = 0.0, az = 0.0, bx = 0.0, bz = 0.0;
    double dot = 0.0;
    double cross = 0.0;
};

void accumulate_planar_sums(PlanarCrossSums& sums, vec3 a, vec3 b, double weight);

// θ = atan2(Σw(x z' − z x') − (x̄ z̄' − z̄ x̄')/W,  Σw(x x' + z z') − (x̄ x̄' + z̄ z̄')/W),
// translation from the weighted centroids (Kovar et al. 2002, eqs. 2–4).
PlanarTransform align_from_sums(const PlanarCrossSums& sums);

// The alignment of `b` onto `a` (same length, one weight per point).
PlanarTransform align_point_clouds(std::span<const vec3> a, std::span<const vec3> b, std::span<const float> weights);

// Σ w |a − T(b)|² for a given transform, in double.
double planar_cloud_distance(std::span<const vec3> a, std::span<const vec3> b, std::span<const float> weights,
                             const PlanarTransform& t);

}  // namespace marionette
