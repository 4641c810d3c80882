#include "runtime/math/det_math.hpp"

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace marionette::det {

namespace {
// pi/2 split so that q*kPio2Hi is exact for |q| < 2^20.
constexpr double kPio2Hi = 1.57079632673412561417e+00;
constexpr double kPio2Lo = 6.07710050650619224932e-11;

// c[0]·x^(N−1) + c[1]·x^(N−2) + ... + c[N−1] by Horner's rule: one multiply
// then one add per coefficient, in that order (no contraction: exact IEEE steps).
// Adding a negative coefficient is the same IEEE operation as subtracting its
// magnitude.
template <std::size_t N>
double horner(double x, const std::array<double, N>& c) {
    double p = c[0];
    for (std::size_t i = 1; i < N; ++i) p = p * x + c[i];
    return p;
}

// (sin r − r) / r³ in powers of r², Taylor terms up to r^17: error < (pi/4)^19/19! ~ 1e-18.
constexpr std::array<double, 8> kSinTerms = {
    1.0 / 355687428096000.0,  // 1/17!
    -1.0 / 1307674368000.0,   // 1/15!
    1.0 / 6227020800.0,       // 1/13!
    -1.0 / 39916800.0,        // 1/11!
    1.0 / 362880.0,           // 1/9!
    -1.0 / 5040.0,            // 1/7!
    1.0 / 120.0,              // 1/5!
    -1.0 / 6.0,               // 1/3!
};

// (1 − cos r) / r² in powers of r², Taylor terms up to r^18.
constexpr std::array<double, 9> kCosTerms = {
    1.0 / 6402373705728000.0,  // 1/18!
    -1.0 / 20922789888000.0,   // 1/16!
    1.0 / 87178291200.0,       // 1/14!
    -1.0 / 479001600.0,        // 1/12!
    1.0 / 3628800.0,           // 1/10!
    -1.0 / 40320.0,            // 1/8!
    1.0 / 720.0,               // 1/6!
    -1.0 / 24.0,               // 1/4!
    0.5,                       // 1/2!
};

double sin_poly(double r) {
    const double r2 = r * r;
    return r + r * r2 * horner(r2, kSinTerms);
}

double cos_poly(double r) {
    const double r2 = r * r;
    return 1.0 - r2 * horner(r2, kCosTerms);
}

// atan on [0, tan(pi/8)] by its Taylor series (alternating, 0.4142^35/35 < 1e-15).
// The coefficients ±1/(2k + 1), k = 0..16, computed once at compile time by the
// same IEEE division the loop did per call (the same bits): with 17 run-time
// divisions a call it took 225 instructions, now 129.
constexpr std::array<double, 17> kAtanTerms = [] {
    std::array<double, 17> out{};
    for (int k = 0; k <= 16; ++k) {
        const double term = 1.0 / static_cast<double>(2 * k + 1);
        out[static_cast<std::size_t>(k)] = (k % 2 == 0) ? term : -term;
    }
    return out;
}();

double atan_small(double x) {
    const double x2 = x * x;
    double p = 0.0;
    for (int k = 16; k >= 0; --k) p = p * x2 + kAtanTerms[static_cast<std::size_t>(k)];
    return x * p;
}
}  // namespace

void sin_cos(double x, double& s, double& c) {
    if (!std::isfinite(x)) {
        s = c = x - x;  // NaN
        return;
    }
    // Very large arguments lose all meaning in float simulation anyway; reduce
    // them first so q stays in range for the exact split. fmod is exact (the
    // remainder of two doubles is representable), so this is the same on every
    // machine; x - 2pi * nearbyint(x / 2pi) was not a reduction above ~1e22 (a
    // stick program's `from=7.7e77` left q out of int64's range: UB, found by
    // fuzz_stick_program).
    if (x > 1.0e6 || x < -1.0e6) x = std::fmod(x, kTwoPi);
    const double q = std::nearbyint(x / kHalfPi);
    const double r = (x - q * kPio2Hi) - q * kPio2Lo;
    const double sr = sin_poly(r);
    const double cr = cos_poly(r);
    const int quadrant = static_cast<int>(static_cast<std::int64_t>(q) & 3);
    switch (quadrant) {
        case 0: s = sr; c = cr; break;
        case 1: s = cr; c = -sr; break;
        case 2: s = -sr; c = -cr; break;
        default: s = -cr; c = sr; break;
    }
}

double atan(double x) {
    if (std::isnan(x)) return x;
    const bool negative = x < 0.0;
    double a = negative ? -x : x;
    double result;
    constexpr double kTan3Pi8 = 2.41421356237309504880;  // tan(3pi/8)
    constexpr double kTanPi8 = 0.41421356237309504880;   // tan(pi/8)
    if (a > kTan3Pi8) {
        result = kHalfPi - atan_small(1.0 / a);
    } else if (a > kTanPi8) {
        result = kPi / 4.0 + atan_small((a - 1.0) / (a + 1.0));
    } else {
        result = atan_small(a);
    }
    return negative ? -result : result;
}

double atan2(double y, double x) {
    if (std::isnan(x) || std::isnan(y)) return x + y;
    if (x == 0.0) {
        if (y > 0.0) return kHalfPi;
        if (y < 0.0) return -kHalfPi;
        return std::signbit(x) ? (std::signbit(y) ? -kPi : kPi) : y;
    }
    const double base = atan(y / x);
    if (x > 0.0) return base;
    return (y >= 0.0) ? base + kPi : base - kPi;
}

double acos(double x) {
    if (std::isnan(x)) return x;
    if (x > 1.0) x = 1.0;
    if (x < -1.0) x = -1.0;
    return atan2(std::sqrt((1.0 - x) * (1.0 + x)), x);
}

double asin(double x) {
    if (std::isnan(x)) return x;
    if (x > 1.0) x = 1.0;
    if (x < -1.0) x = -1.0;
    return atan2(x, std::sqrt((1.0 - x) * (1.0 + x)));
}

double wrap_angle(double radians) {
    if (!std::isfinite(radians)) return 0.0;
    // Already in (−pi, pi]: radians / 2pi lies in [−0.5, 0.5] and rounds to ±0,
    // so the formula below gives radians − (±0), which is radians, except −0,
    // which it turns into +0 (as adding +0 does). Most calls are here (a
    // heading change per predicted tick), and skip the division.
    if (radians > -kPi && radians <= kPi) return radians + 0.0;
    double w = radians - kTwoPi * std::nearbyint(radians / kTwoPi);
    if (w <= -kPi) w += kTwoPi;
    if (w > kPi) w -= kTwoPi;
    return w;
}

}  // namespace marionette::det
