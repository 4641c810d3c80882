#pragma once
// One owned implementation of the transcendental functions the simulation needs.
// libm's sin/cos/atan2 may differ in the last bit between glibc versions, musl and
// architectures; these use only +,-,*,/ and sqrt, so with FP contraction off they
// give the same bits everywhere. Accuracy is about 1e-15 relative in double.
#include <cmath>

namespace marionette::det {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kHalfPi = 1.57079632679489661923;
inline constexpr double kTwoPi = 6.28318530717958647692;
inline constexpr double kDegToRad = kPi / 180.0;
inline constexpr double kRadToDeg = 180.0 / kPi;

// sin and cos together: reduce x to r in [-pi/4, pi/4] with x = r + q*pi/2
// (Cody–Waite split of pi/2), then Taylor polynomials on r.
void sin_cos(double x, double& s, double& c);
inline double sin(double x) { double s, c; sin_cos(x, s, c); return s; }
inline double cos(double x) { double s, c; sin_cos(x, s, c); return c; }

double atan(double x);
double atan2(double y, double x);
// Arguments outside [-1, 1] are clamped (rounding noise from dot products).
double acos(double x);
double asin(double x);

// Wrap an angle to (-pi, pi].
double wrap_angle(double radians);

}  // namespace marionette::det
