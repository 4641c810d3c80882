#include "graph_builder/distance_bound.hpp"

#include <algorithm>
#include <cmath>

namespace marionette::offline {

namespace {

constexpr double kUnitRoundoff = 0x1p-53;  // u: |fl(x op y) − x op y| ≤ u·|x op y|

// γ_n = n·u / (1 − n·u): a sum of n products, in any order and with or without
// fused multiply-adds, is off by at most γ_n · Σ|products| (Higham, Accuracy and
// Stability of Numerical Algorithms, §3.1; a blocked or vectorised BLAS kernel is
// one such order).
double gamma(double n) { return n * kUnitRoundoff / (1.0 - n * kUnitRoundoff); }

}  // namespace

// The derivation, per pair. Inputs are the features' doubles, the same in both
// computations; "exact" below means exact arithmetic on those doubles.
// Magnitudes (Cauchy–Schwarz per frame, then over the k frames of the window):
//   Rx2 = max_f |xz_f|² (= |zx_f|²), Ry2 = max_f |y_f|², C2 = max_f (cx² + cz²)
//   Pd = k·Rx2 ≥ Σ|xz_a·xz_b| over the window, Py = k·Ry2, Pc = k·C2, Q = W·Pc
//   Mdot = Pd + 2Q ≥ |dot|, |cross| (and their parts); Mr = √2·Mdot ≥ √(dot² + cross²)
//   Md = 2·Smax + 2·Py + 2·Mr ≥ the sum of |terms| of D = S_A + S_B − 2Y − 2√(dot² + cross²)
// Tiled search (transition_search.cpp's run_tile):
//   a dgemm product is off by ≤ γ_{2J}·Rx2 (γ_J·Ry2 for y);
//   a window sum is its k products' sum (the sliding telescopes: the product that
//   leaves is the same double that entered) plus the additions' roundings: k − 1 in
//   the direct first row (≤ γ_k·Pd) and two per slide on values ≤ (k + 2)·Rx2;
//   the centroid sums, recomputed at every slide, add γ_2·C2 per term entering or leaving;
//   dot = s + (W·s_c − A·B/k·W): ≤ 10 roundings on values ≤ Mdot;
//   √(dot² + cross²) moves by ≤ |Δdot| + |Δcross| plus 3 roundings on ≤ Mr;
//   D: 3 roundings on ≤ Md; the normalisation 1 / (W·k): 4 more on ≤ Md.
// Fixed-order kernel (feature_pair_distance): one sequential sum of 2J·k products
// (≤ γ_{2Jk}·Pd), of J·k (≤ γ_{Jk}·Py), the centroid sums (≤ (γ_2 + γ_k)·Pc), then
// the same combination. The sum of both errors is doubled (second-order terms,
// maxima taken in rounded arithmetic) and widened by the rounding of v ± bound.
DistanceErrorBound window_distance_error_bound(const FrameFeatures& f, std::int32_t max_slides) {
    const double u = kUnitRoundoff;
    const size_t n = static_cast<size_t>(f.frames), J = static_cast<size_t>(f.joints);
    double rx2 = 0.0, ry2 = 0.0, c2 = 0.0, smax = 0.0;
    for (size_t fr = 0; fr < n; ++fr) {
        double x = 0.0, y = 0.0;
        for (size_t q = 0; q < 2 * J; ++q) x += f.xz[fr * 2 * J + q] * f.xz[fr * 2 * J + q];
        for (size_t q = 0; q < J; ++q) y += f.y[fr * J + q] * f.y[fr * J + q];
        rx2 = std::max(rx2, x);
        ry2 = std::max(ry2, y);
        c2 = std::max(c2, f.cx[fr] * f.cx[fr] + f.cz[fr] * f.cz[fr]);
        if (f.start_ok[fr]) smax = std::max(smax, std::abs(f.window_spread[fr]));
    }
    const double k = f.window, w = f.weight, m = std::max(max_slides, 0);
    const double dj = static_cast<double>(J);
    const double pd = k * rx2, py = k * ry2, pc = k * c2, q = w * pc;
    const double mdot = pd + 2.0 * q, mr = std::sqrt(2.0) * mdot, md = 2.0 * smax + 2.0 * py + 2.0 * mr;
    const double slack = 1.01;  // magnitudes grown by their own (tiny) errors

    DistanceErrorBound b;
    b.product_xz = gamma(2.0 * dj) * rx2;
    b.product_y = gamma(dj) * ry2;
    // Tiled.
    const double t_sd = slack * (k * b.product_xz + gamma(k) * pd + m * 2.0 * u * (k + 2.0) * rx2);
    const double t_sy = slack * (k * b.product_y + gamma(k) * py + m * 2.0 * u * (k + 2.0) * ry2);
    const double t_sc = slack * (k * gamma(2.0) * c2 + gamma(k) * pc + m * (2.0 * gamma(2.0) + 2.0 * u * (k + 2.0)) * c2);
    const double t_dot = t_sd + w * t_sc + 10.0 * u * mdot;
    const double t_r = 2.0 * t_dot + 3.0 * u * mr;
    const double t_d = 2.0 * t_sy + 2.0 * t_r + 3.0 * u * md;
    // Fixed order.
    const double f_sd = gamma(2.0 * dj * k) * pd;
    const double f_sy = gamma(dj * k) * py;
    const double f_sc = slack * (gamma(2.0) + gamma(k)) * pc;
    const double f_dot = f_sd + w * f_sc + 10.0 * u * mdot;
    const double f_r = 2.0 * f_dot + 3.0 * u * mr;
    const double f_d = 2.0 * f_sy + 2.0 * f_r + 3.0 * u * md;

    const double wk = w * k;
    const double both = (t_d + f_d + 8.0 * u * md) / wk;
    // The bound is subtracted from and added to v in double: that rounding (≤ u·(|v| + bound),
    // |v| ≤ Md / (W·k)) is covered by the margin; 1e-300 covers flushed subnormals.
    b.distance = 2.0 * both + 4.0 * u * md / wk + 1e-300;
    return b;
}

}  // namespace marionette::offline
