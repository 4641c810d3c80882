#include "runtime/math/hermite_spline.hpp"

#include <cmath>

namespace marionette {

namespace {
float length_of(vec3 v) { return std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z); }

// Index of the segment [keys[i], keys[i+1]] holding `time` (keys.size() >= 2).
std::size_t segment_of(std::span<const HermiteKey> keys, float time) {
    std::size_t lo = 0;
    std::size_t hi = keys.size() - 1;
    while (hi - lo > 1) {
        const std::size_t mid = (lo + hi) / 2;
        if (keys[mid].time <= time) lo = mid;
        else hi = mid;
    }
    return lo;
}

// segment_of(keys, time), trying `hint` first (the segment the previous lookup
// found): the segment holding a time is the one i with keys[i].time <= time <
// keys[i + 1].time, unique for sorted keys, and the binary search above returns
// exactly that i, so a hint that brackets the time is the same answer. The
// arc-length work looks up many times inside one table interval, and every
// interval of a swing path lies inside one key segment.
std::size_t segment_near(std::span<const HermiteKey> keys, float time, std::size_t& hint) {
    if (!(hint + 1 < keys.size() && keys[hint].time <= time && time < keys[hint + 1].time)) hint = segment_of(keys, time);
    return hint;
}
}  // namespace

namespace {
// The position and the velocity at fraction s of the segment from a to b
// (h = b.time − a.time > 0): every sampler computes them here, so the position
// alone and the speed alone are the full sample's bits.
[[gnu::always_inline]] inline vec3 segment_position(const HermiteKey& a, const HermiteKey& b, float h, float s) {
    const HermiteBasis w = hermite_basis(s);
    return a.position * w.h00 + a.tangent * (w.h10 * h) + b.position * w.h01 + b.tangent * (w.h11 * h);
}
[[gnu::always_inline]] inline vec3 segment_velocity(const HermiteKey& a, const HermiteKey& b, float h, float s) {
    const HermiteBasis d = hermite_basis_derivative(s);
    return (a.position * d.h00 + a.tangent * (d.h10 * h) + b.position * d.h01 + b.tangent * (d.h11 * h)) / h;
}

// sample_hermite(keys, time).velocity without the position: the same branches
// and the same arithmetic, for the arc-length integration and the Newton steps,
// which read only the speed (half of sample_hermite's work was a position they dropped).
vec3 hermite_velocity(std::span<const HermiteKey> keys, float time, std::size_t& hint) {
    if (keys.size() < 2 || !(time > keys.front().time) || !(time < keys.back().time)) return vec3(0.0f);
    const std::size_t i = segment_near(keys, time, hint);
    const HermiteKey& a = keys[i];
    const HermiteKey& b = keys[i + 1];
    const float h = b.time - a.time;
    if (!(h > 0.0f)) return vec3(0.0f);
    return segment_velocity(a, b, h, (time - a.time) / h);
}

// Length of the curve over [t0, t1]: 3-point Gauss–Legendre on |velocity|
// (nodes 0, ±sqrt(3/5), weights 8/9, 5/9).
float gauss_length(std::span<const HermiteKey> keys, float t0, float t1, std::size_t& hint) {
    const float node = 0.7745966692414834f;
    const float mid = 0.5f * (t0 + t1);
    const float half = 0.5f * (t1 - t0);
    const float speed_mid = length_of(hermite_velocity(keys, mid, hint));
    const float speed_lo = length_of(hermite_velocity(keys, mid - half * node, hint));
    const float speed_hi = length_of(hermite_velocity(keys, mid + half * node, hint));
    return half * ((8.0f / 9.0f) * speed_mid + (5.0f / 9.0f) * (speed_lo + speed_hi));
}
}  // namespace

HermiteBasis hermite_basis(float s) {
    const float s2 = s * s;
    const float s3 = s2 * s;
    return {2.0f * s3 - 3.0f * s2 + 1.0f, s3 - 2.0f * s2 + s, -2.0f * s3 + 3.0f * s2, s3 - s2};
}

HermiteBasis hermite_basis_derivative(float s) {
    const float s2 = s * s;
    return {6.0f * s2 - 6.0f * s, 3.0f * s2 - 4.0f * s + 1.0f, -6.0f * s2 + 6.0f * s, 3.0f * s2 - 2.0f * s};
}

HermiteSample sample_hermite(std::span<const HermiteKey> keys, float time) {
    if (keys.empty()) return {};
    if (keys.size() == 1 || !(time > keys.front().time)) return {keys.front().position, vec3(0.0f)};
    if (!(time < keys.back().time)) return {keys.back().position, vec3(0.0f)};
    const std::size_t i = segment_of(keys, time);
    const HermiteKey& a = keys[i];
    const HermiteKey& b = keys[i + 1];
    const float h = b.time - a.time;
    if (!(h > 0.0f)) return {b.position, vec3(0.0f)};
    const float s = (time - a.time) / h;
    return {segment_position(a, b, h, s), segment_velocity(a, b, h, s)};
}

vec3 sample_hermite_position(std::span<const HermiteKey> keys, float time) {
    if (keys.empty()) return vec3(0.0f);
    if (keys.size() == 1 || !(time > keys.front().time)) return keys.front().position;
    if (!(time < keys.back().time)) return keys.back().position;
    const std::size_t i = segment_of(keys, time);
    const HermiteKey& a = keys[i];
    const HermiteKey& b = keys[i + 1];
    const float h = b.time - a.time;
    if (!(h > 0.0f)) return b.position;
    return segment_position(a, b, h, (time - a.time) / h);
}

ArcLengthTable build_arc_length_table(std::span<const HermiteKey> keys) {
    ArcLengthTable table;
    if (keys.size() < 2) return table;
    table.start_time = keys.front().time;
    table.end_time = keys.back().time;
    const float span = table.end_time - table.start_time;
    const float dt = span / static_cast<float>(kArcLengthIntervals);
    std::size_t hint = 0;
    for (int i = 0; i < kArcLengthIntervals; ++i) {
        const float t0 = table.start_time + dt * static_cast<float>(i);
        const float piece = gauss_length(keys, t0, t0 + dt, hint);
        table.length[static_cast<std::size_t>(i) + 1] = table.length[static_cast<std::size_t>(i)] + piece;
    }
    return table;
}

float time_at_arc_length(std::span<const HermiteKey> keys, const ArcLengthTable& table, float distance) {
    if (keys.size() < 2 || !(table.total() > 0.0f)) return table.start_time;
    if (!(distance > 0.0f)) return table.start_time;
    if (!(distance < table.total())) return table.end_time;
    std::size_t lo = 0;
    std::size_t hi = kArcLengthIntervals;
    while (hi - lo > 1) {
        const std::size_t mid = (lo + hi) / 2;
        if (table.length[mid] <= distance) lo = mid;
        else hi = mid;
    }
    const float dt = (table.end_time - table.start_time) / static_cast<float>(kArcLengthIntervals);
    const float t_lo = table.start_time + dt * static_cast<float>(lo);
    const float piece = table.length[lo + 1] - table.length[lo];
    float t = t_lo + (piece > 0.0f ? (distance - table.length[lo]) / piece : 0.0f) * dt;
    // Safeguarded Newton on f(t) = length(t) − distance, length(t) integrated
    // from the bracket start with the same Gauss–Legendre rule: each step
    // narrows [a, b] around the root, and a step that would leave it bisects
    // instead (where the speed changes sharply inside the bracket, as on a
    // curve that climbs steeply and then runs flat, plain Newton overshoots).
    float a = t_lo, b = t_lo + dt;
    std::size_t hint = 0;
    for (int iteration = 0; iteration < 3; ++iteration) {
        const float covered = table.length[lo] + gauss_length(keys, t_lo, t, hint);
        if (covered < distance) a = t;
        else b = t;
        const float speed_t = length_of(hermite_velocity(keys, t, hint));
        float next = speed_t > 1e-6f ? t - (covered - distance) / speed_t : 0.5f * (a + b);
        if (!(next >= a && next <= b)) next = 0.5f * (a + b);
        t = next;
    }
    return t;
}

}  // namespace marionette
