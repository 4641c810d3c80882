#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "runtime/math/hermite_spline.hpp"

using namespace marionette;

namespace {
float distance(vec3 a, vec3 b) {
    const vec3 d = a - b;
    return std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
}
// A cubic per axis, which a Hermite spline with exact positions and derivatives
// at its keys must reproduce everywhere.
vec3 cubic(float t) { return vec3(t * t * t - 2 * t * t + 3, 0.5f * t * t * t + t, -t * t + 4 * t - 1); }
vec3 cubic_derivative(float t) { return vec3(3 * t * t - 4 * t, 1.5f * t * t + 1, -2 * t + 4); }
}  // namespace

TEST_CASE("hermite basis is a partition of unity with the right end values", "[spline]") {
    for (float s = 0.0f; s <= 1.0f; s += 0.125f) {
        const HermiteBasis b = hermite_basis(s);
        CHECK(b.h00 + b.h01 == Approx(1.0f));
        const HermiteBasis d = hermite_basis_derivative(s);
        CHECK(d.h00 + d.h01 == Approx(0.0f).margin(1e-6));
    }
    const HermiteBasis at0 = hermite_basis(0.0f);
    const HermiteBasis at1 = hermite_basis(1.0f);
    CHECK(at0.h00 == 1.0f);
    CHECK(at0.h10 == 0.0f);
    CHECK(at1.h01 == 1.0f);
    CHECK(at1.h11 == 0.0f);
    CHECK(hermite_basis_derivative(0.0f).h10 == 1.0f);
    CHECK(hermite_basis_derivative(1.0f).h11 == 1.0f);
}

TEST_CASE("hermite spline reproduces a cubic and its derivative over uneven keys", "[spline]") {
    const float times[] = {0.0f, 0.5f, 2.0f, 2.25f};
    HermiteKey keys[4];
    for (int i = 0; i < 4; ++i) keys[i] = {times[i], cubic(times[i]), cubic_derivative(times[i])};
    for (float t = 0.01f; t < 2.25f; t += 0.0371f) {
        const HermiteSample s = sample_hermite(keys, t);
        CHECK(distance(s.position, cubic(t)) < 1e-4f);
        CHECK(distance(s.velocity, cubic_derivative(t)) < 1e-3f);
    }
}

TEST_CASE("hermite spline clamps to its end keys outside their times", "[spline]") {
    const HermiteKey keys[] = {{1.0f, vec3(1, 2, 3), vec3(5, 0, 0)}, {2.0f, vec3(4, 5, 6), vec3(0, 5, 0)}};
    CHECK(sample_hermite(keys, 0.0f).position == vec3(1, 2, 3));
    CHECK(sample_hermite(keys, 3.0f).position == vec3(4, 5, 6));
    CHECK(sample_hermite(keys, 3.0f).velocity == vec3(0.0f));
    CHECK(sample_hermite(std::span<const HermiteKey>(keys, 1), 1.5f).position == vec3(1, 2, 3));
    CHECK(sample_hermite({}, 1.5f).position == vec3(0.0f));
}

TEST_CASE("arc length of a straight ease-in-out segment is its length and reparameterises evenly", "[spline]") {
    // Zero end tangents: the point speeds up then slows down along the line.
    const HermiteKey keys[] = {{0.0f, vec3(0, 0, 0), vec3(0.0f)}, {1.0f, vec3(3, 4, 0), vec3(0.0f)}};
    const ArcLengthTable table = build_arc_length_table(keys);
    CHECK(table.total() == Approx(5.0f).epsilon(1e-5));
    for (float s = 0.0f; s <= 5.0f; s += 0.25f) {
        const float t = time_at_arc_length(keys, table, s);
        CHECK(distance(sample_hermite(keys, t).position, vec3(0.0f)) == Approx(s).margin(1e-4));
    }
}

TEST_CASE("arc length of the parabola y = x squared matches its closed form", "[spline]") {
    // Position (t, t²) has derivative (1, 2t): keys at t = 0 and 1 reproduce it exactly.
    const HermiteKey keys[] = {{0.0f, vec3(0, 0, 0), vec3(1, 0, 0)}, {1.0f, vec3(1, 1, 0), vec3(1, 2, 0)}};
    const ArcLengthTable table = build_arc_length_table(keys);
    const double exact = std::sqrt(5.0) / 2.0 + std::asinh(2.0) / 4.0;  // ∫₀¹ √(1 + 4x²) dx
    CHECK(table.total() == Approx(exact).epsilon(1e-5));
    // Halfway along the curve by length: ∫₀ˣ √(1 + 4u²) du = exact / 2.
    const float t = time_at_arc_length(keys, table, static_cast<float>(exact / 2.0));
    const double x = t;
    const double covered = x / 2.0 * std::sqrt(1.0 + 4.0 * x * x) + std::asinh(2.0 * x) / 4.0;
    CHECK(covered == Approx(exact / 2.0).epsilon(1e-5));
    CHECK(time_at_arc_length(keys, table, -1.0f) == 0.0f);
    CHECK(time_at_arc_length(keys, table, 10.0f) == 1.0f);
}

// The position-only sampler gives sample_hermite's position bit for bit on
// generated curves: 0 to 8 keys, uneven and repeated times (zero-length
// segments), times before, inside, on and after the keys, NaN.
TEST_CASE("sample_hermite_position is sample_hermite's position, bit for bit", "[spline]") {
    std::mt19937 rng(41);
    std::uniform_real_distribution<float> value(-2.0f, 2.0f), gap(0.0f, 0.5f), unit(0.0f, 1.0f);
    std::uniform_int_distribution<int> count(0, 8), pick(0, 9);
    int compared = 0;
    for (int c = 0; c < 3000; ++c) {
        std::vector<HermiteKey> keys(static_cast<std::size_t>(count(rng)));
        float t = value(rng);
        for (HermiteKey& k : keys) {
            t += pick(rng) == 0 ? 0.0f : gap(rng);  // sometimes a repeated time
            k.time = t;
            k.position = vec3(value(rng), value(rng), value(rng));
            k.tangent = vec3(value(rng), value(rng), value(rng));
        }
        const std::span<const HermiteKey> span(keys);
        const float first = keys.empty() ? 0.0f : keys.front().time, last = keys.empty() ? 1.0f : keys.back().time;
        for (int q = 0; q < 40; ++q) {
            float time = first - 0.5f + (last - first + 1.0f) * unit(rng);
            if (q == 0) time = first;
            if (q == 1) time = last;
            if (q == 2) time = std::nanf("");
            if (q == 3 && !keys.empty()) time = keys[keys.size() / 2].time;
            const vec3 full = sample_hermite(span, time).position;
            const vec3 only = sample_hermite_position(span, time);
            INFO("case " << c << " time " << time);
            REQUIRE(std::memcmp(&full, &only, sizeof full) == 0);
            ++compared;
        }
    }
    CHECK(compared == 120000);
}
