// The owned transcendental functions against libm (which is allowed here, in a
// test, as the independent reference) over dense grids and edge cases.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "runtime/math/det_math.hpp"
#include "runtime/math/math.hpp"

using namespace marionette;

TEST_CASE("det::sin_cos matches libm to 1e-14 over many turns", "[det_math]") {
    double worst = 0.0;
    for (int i = -200000; i <= 200000; ++i) {
        const double x = i * 0.000731;  // about ±146 rad
        double s = 0.0, c = 0.0;
        det::sin_cos(x, s, c);
        worst = std::max({worst, std::abs(s - std::sin(x)), std::abs(c - std::cos(x))});
    }
    CHECK(worst < 1e-14);
    CHECK(det::sin(0.0) == 0.0);
    CHECK(det::cos(0.0) == 1.0);
    CHECK(std::isnan(det::sin(std::nan(""))));
}

TEST_CASE("det::atan2, acos and asin match libm", "[det_math]") {
    double worst = 0.0;
    for (int i = 0; i < 3600; ++i) {
        const double a = i * (det::kTwoPi / 3600.0) - det::kPi + 1e-7;
        for (double r : {1e-6, 0.5, 1.0, 1234.5}) {
            const double y = r * std::sin(a);
            const double x = r * std::cos(a);
            worst = std::max(worst, std::abs(det::atan2(y, x) - std::atan2(y, x)));
        }
    }
    CHECK(worst < 1e-14);
    for (int i = -1000; i <= 1000; ++i) {
        const double x = i / 1000.0;
        CHECK(std::abs(det::acos(x) - std::acos(x)) < 1e-7);  // acos is ill-conditioned at ±1
        CHECK(std::abs(det::asin(x) - std::asin(x)) < 1e-7);
        if (std::abs(x) < 0.99) {
            CHECK(std::abs(det::acos(x) - std::acos(x)) < 1e-14);
            CHECK(std::abs(det::asin(x) - std::asin(x)) < 1e-14);
        }
    }
    CHECK(det::acos(1.0000001) == 0.0);  // clamped, not NaN
    CHECK(det::atan2(0.0, -1.0) == Approx(det::kPi));
    CHECK(det::atan2(-1.0, 0.0) == Approx(-det::kHalfPi));
}

TEST_CASE("wrap_angle maps into the interval from -pi (excluded) to pi", "[det_math]") {
    CHECK(det::wrap_angle(3 * det::kPi) == Approx(det::kPi));
    CHECK(det::wrap_angle(-det::kPi) == Approx(det::kPi));
    CHECK(det::wrap_angle(0.25) == Approx(0.25));
    CHECK(det::wrap_angle(det::kTwoPi + 0.25) == Approx(0.25));
}

namespace {
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
}  // namespace

// wrap_angle returns an angle already in (−pi, pi] without its division: the
// same bits as the formula (radians − 2pi·nearbyint(radians / 2pi), then one
// turn added or taken off at the ends), −0 included (the formula gives +0).
TEST_CASE("wrap_angle gives the formula's bits inside its interval and outside it", "[det_math]") {
    const auto formula = [](double r) {
        double w = r - det::kTwoPi * std::nearbyint(r / det::kTwoPi);
        if (w <= -det::kPi) w += det::kTwoPi;
        if (w > det::kPi) w -= det::kTwoPi;
        return w;
    };
    std::mt19937_64 rng(31);
    std::uniform_real_distribution<double> near(-4.0, 4.0), far(-1e7, 1e7);
    std::vector<double> values = {0.0, -0.0, det::kPi, -det::kPi, std::nextafter(det::kPi, 0.0), std::nextafter(det::kPi, 4.0),
                                  std::nextafter(-det::kPi, 0.0), std::nextafter(-det::kPi, -4.0), det::kTwoPi, -det::kTwoPi,
                                  1e-300, -1e-300, 3.0 * det::kPi, -3.0 * det::kPi, 1e300, -1e300};
    for (int i = 0; i < 200000; ++i) values.push_back(i % 2 ? near(rng) : far(rng));
    for (double r : values) {
        INFO(r);
        REQUIRE(same_bits(det::wrap_angle(r), formula(r)));
    }
    CHECK(std::signbit(det::wrap_angle(-0.0)) == false);
}

// atan's Taylor coefficients are a table computed at compile time; the same
// series with each coefficient divided out at run time, as it was, gives the
// same bits.
TEST_CASE("det::atan gives the bits of the series with run-time coefficients", "[det_math]") {
    const auto small = [](double x) {
        const double x2 = x * x;
        double p = 0.0;
        for (int k = 16; k >= 0; --k) {
            const double term = 1.0 / static_cast<double>(2 * k + 1);
            p = p * x2 + ((k % 2 == 0) ? term : -term);
        }
        return x * p;
    };
    const auto reference = [&](double x) {
        const bool negative = x < 0.0;
        const double a = negative ? -x : x;
        double result;
        if (a > 2.41421356237309504880) result = det::kHalfPi - small(1.0 / a);
        else if (a > 0.41421356237309504880) result = det::kPi / 4.0 + small((a - 1.0) / (a + 1.0));
        else result = small(a);
        return negative ? -result : result;
    };
    std::mt19937_64 rng(32);
    std::uniform_real_distribution<double> unit(-3.0, 3.0);
    for (int i = 0; i < 100000; ++i) {
        const double x = i % 3 == 0 ? unit(rng) : (i % 3 == 1 ? std::ldexp(unit(rng), i % 40 - 20) : 1.0 / unit(rng));
        INFO(x);
        REQUIRE(same_bits(det::atan(x), reference(x)));
    }
}

TEST_CASE("quaternion helpers agree with GLM's reference implementations", "[math]") {
    const quat a = quat_axis_angle(glm::normalize(vec3(1, 2, 3)), 0.7);
    const quat b = quat_axis_angle(glm::normalize(vec3(-2, 1, 0.5)), 2.1);
    const quat ga = glm::angleAxis(0.7f, glm::normalize(vec3(1, 2, 3)));
    CHECK(quat_angle_between(a, ga) < 1e-6);
    const quat prod = quat_mul(a, b);
    const quat gprod = ga * glm::angleAxis(2.1f, glm::normalize(vec3(-2, 1, 0.5)));
    CHECK(quat_angle_between(prod, gprod) < 1e-6);
    const vec3 v(0.3f, -1.2f, 2.0f);
    const vec3 r = quat_rotate(a, v);
    const vec3 gr = ga * v;
    CHECK(glm::length(r - gr) < 1e-6f);
    for (float t : {0.0f, 0.25f, 0.5f, 0.9f, 1.0f}) {
        const quat s = quat_slerp(a, b, t);
        const quat gs = glm::slerp(ga, glm::angleAxis(2.1f, glm::normalize(vec3(-2, 1, 0.5))), t);
        CHECK(quat_angle_between(s, gs) < 1e-5);
    }
    // The interpolation takes the short way even when the inputs are on opposite hemispheres.
    const quat neg_b(-b.w, -b.x, -b.y, -b.z);
    CHECK(quat_angle_between(quat_slerp(a, b, 0.5f), quat_slerp(a, neg_b, 0.5f)) < 1e-6);
}
