#pragma once
// Cubic Hermite splines: a position and a tangent (velocity, d position / d time)
// per key, keys at increasing times. Evaluation, derivative, and an arc-length
// table that turns "distance along the curve" back into time, so a limb can be
// moved along a curved path at a chosen speed. Plain functions on spans; nothing
// here allocates, so the tick can build and sample splines freely.
#include <array>
#include <span>

#include "runtime/math/math.hpp"

namespace marionette {

struct HermiteKey {
    float time = 0.0f;
    vec3 position{0.0f};
    vec3 tangent{0.0f};  // velocity at the key, units per second
};

struct HermiteSample {
    vec3 position{0.0f};
    vec3 velocity{0.0f};  // d position / d time
};

// The four cubic Hermite basis functions at s in [0, 1] (and their derivatives).
struct HermiteBasis {
    float h00, h10, h01, h11;
};
HermiteBasis hermite_basis(float s);
HermiteBasis hermite_basis_derivative(float s);

// Position and velocity at `time`. Outside [first key, last key] the curve is
// clamped to the end key (velocity zero there), so a finished swing stays put.
// One key: that key's position. No keys: the origin.
HermiteSample sample_hermite(std::span<const HermiteKey> keys, float time);
// sample_hermite(keys, time).position alone: the same branches and the same
// arithmetic, without the velocity (its basis derivative and division), for
// the callers that read only where the curve is.
vec3 sample_hermite_position(std::span<const HermiteKey> keys, float time);

// Cumulative arc length at evenly spaced times over the keys' span, so that
// distance along the curve maps back to time (arc-length reparameterisation).
// Each interval's length is integrated with 3-point Gauss–Legendre on |velocity|.
inline constexpr int kArcLengthIntervals = 32;
struct ArcLengthTable {
    float start_time = 0.0f;
    float end_time = 0.0f;
    std::array<float, kArcLengthIntervals + 1> length{};  // length[0] = 0
    float total() const { return length[kArcLengthIntervals]; }
};
ArcLengthTable build_arc_length_table(std::span<const HermiteKey> keys);

// Time at which the curve has covered `distance` (clamped to [0, total]): the
// table brackets it, two Newton steps on |velocity| refine it.
float time_at_arc_length(std::span<const HermiteKey> keys, const ArcLengthTable& table, float distance);

}  // namespace marionette
