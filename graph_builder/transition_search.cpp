#include "graph_builder/transition_search.hpp"

#include <cblas.h>
#include <sys/mman.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <limits>
#include <map>
#include <new>
#include <memory>
#include <stdexcept>
#include <thread>

#include "graph_builder/distance_bound.hpp"

namespace marionette::offline {

namespace {

int thread_count(int requested) {
    if (requested > 0) return requested;
    const unsigned hw = std::thread::hardware_concurrency();
    return hw > 0 ? static_cast<int>(hw) : 1;
}

// D from the window sums (see FrameFeatures): Ã and B̃ are the alignment's
// centred dot and cross terms; the closed-form minimum over the rotation is
// S_A + S_B − 2·Y − 2·sqrt(Ã² + B̃²).
inline double distance_from_sums(const FrameFeatures& f, std::int32_t i, std::int32_t g, double sum_dot,
                                 double sum_cross, double sum_y) {
    const double k = f.window;
    const size_t ui = static_cast<size_t>(i), ug = static_cast<size_t>(g);
    const double dot = sum_dot, cross = sum_cross;
    const double d = f.window_spread[ui] + f.window_spread[ug] - 2.0 * sum_y - 2.0 * std::sqrt(dot * dot + cross * cross);
    const double v = d / (f.weight * k);
    return v > kDistanceNoiseFloor ? v : 0.0;
}

// +inf, −1 (near-diagonal) or 0 (a pair to evaluate).
inline float pair_status(const FrameFeatures& f, std::int32_t i, std::int32_t j) {
    if (i < 0 || j < 0 || i >= f.frames || j >= f.frames) return kPairInvalid;
    if (!f.start_ok[static_cast<size_t>(i)] || !f.end_ok[static_cast<size_t>(j)]) return kPairInvalid;
    const std::int32_t g = j - f.window + 1;
    if (f.clip_of[static_cast<size_t>(i)] == f.clip_of[static_cast<size_t>(g)] && std::abs(i - g) <= f.window)
        return kPairExcluded;
    return 0.0f;
}

// The local-minimum rule shared by the tiled and the reference search: below the
// threshold, no excluded cell in the neighbourhood, strictly below every earlier
// neighbour (raster order) and not above any later one, so plateaus give one minimum.
template <typename Lookup>
bool is_local_minimum(float v, std::int32_t i, std::int32_t j, int h, double threshold, Lookup&& at) {
    if (v < 0.0f || v >= kPairInvalid || v > threshold) return false;
    for (int di = -h; di <= h; ++di)
        for (int dj = -h; dj <= h; ++dj) {
            if (di == 0 && dj == 0) continue;
            const float u = at(i + di, j + dj);
            if (u < 0.0f || u < v) return false;
            if (u == v && (di < 0 || (di == 0 && dj < 0))) return false;
        }
    return true;
}

}  // namespace

std::vector<std::pair<std::int32_t, std::int32_t>> local_minima(std::span<const float> m, std::int32_t rows,
                                                               std::int32_t cols, int h, double threshold) {
    const auto at = [&](std::int32_t i, std::int32_t j) -> float {
        if (i < 0 || j < 0 || i >= rows || j >= cols) return kPairInvalid;
        return m[static_cast<size_t>(i) * static_cast<size_t>(cols) + static_cast<size_t>(j)];
    };
    std::vector<std::pair<std::int32_t, std::int32_t>> out;
    for (std::int32_t i = 0; i < rows; ++i)
        for (std::int32_t j = 0; j < cols; ++j)
            if (is_local_minimum(at(i, j), i, j, h, threshold, at)) out.push_back({i, j});
    return out;
}

std::vector<vec3> database_positions(const ClipDatabase& db) {
    const size_t joints = static_cast<size_t>(db.skeleton.joint_count());
    std::vector<vec3> out(static_cast<size_t>(db.frame_count()) * joints);
    std::vector<quat> model_rotations(joints);
    size_t frame = 0;
    for (const Clip& clip : db.clips)
        for (int f = 0; f < clip.frame_count; ++f, ++frame) {
            const LocalToModelJob fk{db.skeleton.parents,
                                     {std::span<const quat>(clip.frame_rotations(f), joints),
                                      std::span<const vec3>(clip.frame_translations(f), joints)},
                                     {model_rotations, std::span<vec3>(out.data() + frame * joints, joints)}};
            if (!fk.run()) throw std::invalid_argument("clip database skeleton is not in topological order");
        }
    return out;
}

FrameFeatures compute_frame_features(const ClipDatabase& db, std::span<const vec3> positions, int window, double scale) {
    FrameFeatures f;
    f.frames = static_cast<std::int32_t>(db.frame_count());
    f.joints = db.skeleton.joint_count();
    f.window = window;
    const size_t n = static_cast<size_t>(f.frames), J = static_cast<size_t>(f.joints);
    const double inv_scale = 1.0 / scale;
    std::vector<double> sqrt_w(J);
    for (size_t j = 0; j < J; ++j) {
        f.weight += db.joint_weights[j];
        sqrt_w[j] = std::sqrt(static_cast<double>(db.joint_weights[j]));
    }
    const size_t width = 2 * J;  // xz: √w·q_x…, √w·q_z…
    f.xz.resize(n * width);
    f.zx.resize(n * width);
    f.y.resize(n * J);
    f.cx.resize(n);
    f.cz.resize(n);
    std::vector<double> spread(n);
    f.clip_of.resize(n);
    size_t at = 0;
    for (size_t c = 0; c < db.clips.size(); ++c)
        for (int i = 0; i < db.clips[c].frame_count; ++i) f.clip_of[at++] = static_cast<std::int32_t>(c);
    for (size_t fr = 0; fr < n; ++fr) {
        const vec3* p = positions.data() + fr * J;
        double cx = 0.0, cz = 0.0;
        for (size_t j = 0; j < J; ++j) {
            cx += db.joint_weights[j] * (p[j].x * inv_scale);
            cz += db.joint_weights[j] * (p[j].z * inv_scale);
        }
        f.cx[fr] = cx / f.weight;
        f.cz[fr] = cz / f.weight;
        double s = 0.0;
        for (size_t j = 0; j < J; ++j) {
            const double qx = sqrt_w[j] * (p[j].x * inv_scale - f.cx[fr]), qz = sqrt_w[j] * (p[j].z * inv_scale - f.cz[fr]);
            const double qy = sqrt_w[j] * (p[j].y * inv_scale);
            f.xz[fr * width + j] = qx;
            f.xz[fr * width + J + j] = qz;
            f.zx[fr * width + j] = qz;
            f.zx[fr * width + J + j] = -qx;
            f.y[fr * J + j] = qy;
            s += qx * qx + qz * qz + qy * qy;
        }
        spread[fr] = s;
    }
    // Centroids relative to their clip's mean: the distance ignores any constant
    // ground-plane shift of either window, and small numbers keep float products exact enough.
    for (size_t c = 0, first = 0; c < db.clips.size(); first += static_cast<size_t>(db.clips[c].frame_count), ++c) {
        const size_t count = static_cast<size_t>(db.clips[c].frame_count);
        double mx = 0.0, mz = 0.0;
        for (size_t fr = first; fr < first + count; ++fr) mx += f.cx[fr], mz += f.cz[fr];
        mx /= static_cast<double>(count);
        mz /= static_cast<double>(count);
        for (size_t fr = first; fr < first + count; ++fr) f.cx[fr] -= mx, f.cz[fr] -= mz;
    }
    const size_t k = static_cast<size_t>(window);
    f.start_ok.assign(n, 0);
    f.end_ok.assign(n, 0);
    f.window_spread.assign(n, 0.0);
    f.window_cx.assign(n, 0.0);
    f.window_cz.assign(n, 0.0);
    for (size_t s = 0; s + k <= n; ++s) {
        if (f.clip_of[s] != f.clip_of[s + k - 1]) continue;
        f.start_ok[s] = 1;
        f.end_ok[s + k - 1] = 1;
        double sum = 0.0, sx = 0.0, sz = 0.0, cc = 0.0;
        for (size_t t = 0; t < k; ++t) {
            sum += spread[s + t];
            sx += f.cx[s + t];
            sz += f.cz[s + t];
            cc += f.cx[s + t] * f.cx[s + t] + f.cz[s + t] * f.cz[s + t];
        }
        f.window_cx[s] = sx;
        f.window_cz[s] = sz;
        f.window_spread[s] = sum + f.weight * (cc - (sx * sx + sz * sz) / window);
    }
    return f;
}

double feature_pair_distance(const FrameFeatures& f, std::int32_t i, std::int32_t j) {
    const float status = pair_status(f, i, j);
    if (status != 0.0f) return status;
    const std::int32_t g = j - f.window + 1;
    const size_t J = static_cast<size_t>(f.joints);
    double sd = 0.0, sc = 0.0, sy = 0.0;
    for (int t = 0; t < f.window; ++t) {
        const size_t a = static_cast<size_t>(i + t), b = static_cast<size_t>(g + t);
        const size_t width = 2 * J;
        for (size_t q = 0; q < width; ++q) {
            sd += f.xz[a * width + q] * f.xz[b * width + q];
            sc += f.xz[a * width + q] * f.zx[b * width + q];
        }
        for (size_t q = 0; q < J; ++q) sy += f.y[a * J + q] * f.y[b * J + q];
    }
    // The centroids' part: W·(Σ_t c_a·c_b − ΣA·ΣB / k), as the tiled search adds it.
    double cd = 0.0, cc = 0.0;
    for (int t = 0; t < f.window; ++t) {
        const size_t a = static_cast<size_t>(i + t), b = static_cast<size_t>(g + t);
        cd += f.cx[a] * f.cx[b] + f.cz[a] * f.cz[b];
        cc += f.cx[a] * f.cz[b] - f.cz[a] * f.cx[b];
    }
    const size_t ui = static_cast<size_t>(i), ug = static_cast<size_t>(g);
    sd += f.weight * cd - f.weight / f.window * (f.window_cx[ui] * f.window_cx[ug] + f.window_cz[ui] * f.window_cz[ug]);
    sc += f.weight * cc - f.weight / f.window * (f.window_cx[ui] * f.window_cz[ug] - f.window_cz[ui] * f.window_cx[ug]);
    return distance_from_sums(f, i, g, sd, sc, sy);
}

PlanarTransform reference_pair_alignment(const ClipDatabase& db, std::span<const vec3> positions, int window,
                                         std::int32_t i, std::int32_t j) {
    const size_t J = static_cast<size_t>(db.skeleton.joint_count());
    const std::int32_t g = j - window + 1;
    PlanarCrossSums sums;
    for (int t = 0; t < window; ++t)
        for (size_t q = 0; q < J; ++q)
            accumulate_planar_sums(sums, positions[static_cast<size_t>(i + t) * J + q],
                                   positions[static_cast<size_t>(g + t) * J + q], db.joint_weights[q]);
    return align_from_sums(sums);
}

double reference_pair_distance(const ClipDatabase& db, std::span<const vec3> positions, int window, double scale,
                               std::int32_t i, std::int32_t j, PlanarTransform* align) {
    const size_t J = static_cast<size_t>(db.skeleton.joint_count());
    const std::int32_t g = j - window + 1;
    const PlanarTransform t = reference_pair_alignment(db, positions, window, i, j);
    if (align) *align = t;
    double total = 0.0;
    for (int s = 0; s < window; ++s) {
        const std::span<const vec3> a(positions.data() + static_cast<size_t>(i + s) * J, J);
        const std::span<const vec3> b(positions.data() + static_cast<size_t>(g + s) * J, J);
        total += planar_cloud_distance(a, b, db.joint_weights, t);
    }
    double weight = 0.0;
    for (float w : db.joint_weights) weight += w;
    return total / (weight * window * scale * scale);
}

std::vector<double> distance_percentiles(const FrameFeatures& f, const std::vector<double>& percentiles,
                                         std::int64_t max_samples, int thread_request) {
    // (The sample size: the percentile of 65 536 pairs is within a fraction of a percent.)
    std::vector<std::pair<std::int32_t, std::int32_t>> pairs;
    std::int64_t starts = 0, ends = 0;
    for (std::int32_t i = 0; i < f.frames; ++i) {
        starts += f.start_ok[static_cast<size_t>(i)];
        ends += f.end_ok[static_cast<size_t>(i)];
    }
    if (starts * ends <= max_samples) {
        for (std::int32_t i = 0; i < f.frames; ++i)
            for (std::int32_t j = 0; j < f.frames; ++j)
                if (pair_status(f, i, j) == 0.0f) pairs.push_back({i, j});
    } else {
        std::uint64_t state = 0x9e3779b97f4a7c15ull;  // fixed seed: the same sample every build
        const auto next = [&state](std::int32_t n) {
            state = state * 6364136223846793005ull + 1442695040888963407ull;
            return static_cast<std::int32_t>((state >> 33) % static_cast<std::uint64_t>(n));
        };
        for (std::int64_t tries = 0; static_cast<std::int64_t>(pairs.size()) < max_samples && tries < 20 * max_samples; ++tries) {
            const std::int32_t i = next(f.frames), j = next(f.frames);
            if (pair_status(f, i, j) == 0.0f) pairs.push_back({i, j});
        }
    }
    if (pairs.empty()) return std::vector<double>(percentiles.size(), 0.0);
    std::vector<double> d(pairs.size());
    const int threads = thread_count(thread_request);
    const auto work = [&](int t) {
        for (size_t p = static_cast<size_t>(t); p < pairs.size(); p += static_cast<size_t>(threads))
            d[p] = feature_pair_distance(f, pairs[p].first, pairs[p].second);
    };
    // The calling thread is worker 0: one thread starts no other (no thread is
    // created at all, which also keeps qemu user-mode emulation out of glibc's
    // thread-stack cache, where the aarch64 check was seen to spin).
    std::vector<std::thread> workers;
    for (int t = 1; t < threads; ++t) workers.emplace_back(work, t);
    work(0);
    for (std::thread& w : workers) w.join();
    std::sort(d.begin(), d.end());
    std::vector<double> out;
    for (double p : percentiles)
        out.push_back(d[static_cast<size_t>(std::clamp(p, 0.0, 100.0) / 100.0 * static_cast<double>(d.size() - 1))]);
    return out;
}

namespace {

// out[r * ldc + c] = row (a_first + r) of `a` · row (b_first + c) of `b`, r < a_rows,
// c < b_rows, rows `width` doubles long: every cross term of a tile is one dgemm.
void row_dots(const double* a, std::int32_t a_first, std::int32_t a_rows, const double* b, std::int32_t b_first,
              std::int32_t b_rows, int width, double* out, std::int32_t ldc) {
    cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasTrans, a_rows, b_rows, width, 1.0,
                a + static_cast<size_t>(a_first) * static_cast<size_t>(width), width,
                b + static_cast<size_t>(b_first) * static_cast<size_t>(width), width, 0.0, out, ldc);
}

// The per-row kernels of a tile are cloned for wider vector units where the
// compiler can (the same IEEE adds, multiplies and square roots in the same order
// per lane, and no contraction: every clone gives the same bits).
#if defined(__x86_64__) && defined(__has_attribute)
#if __has_attribute(target_clones)
#define MARIONETTE_VECTOR_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#endif
#endif
#ifndef MARIONETTE_VECTOR_CLONES
#define MARIONETTE_VECTOR_CLONES
#endif

// The five window sums of a tile row, in double, each [c] for pair column c:
// dot, cross and y cross terms (from the sgemm products) and the dot and cross
// products of the frame centroids.
enum WindowSum { kSumDot, kSumCross, kSumY, kSumCentroidDot, kSumCentroidCross, kSumCount };

struct TileTerms {
    const double* dot;   // per-frame cross terms (dgemm), row r at row_at(r): a ring of `ring` rows of nc
    const double* cross;
    const double* y;
    const double* row_cx;  // frame centroids of the tile's rows (nr) and columns (nc)
    const double* row_cz;
    const double* col_cx;
    const double* col_cz;
    size_t nc;
    size_t ring;
    size_t row_at(size_t r) const { return (r % ring) * nc; }
};

// Row r's sums from row r − 1's: pair (r, c)'s k-frame diagonal is pair
// (r − 1, c − 1)'s with frame pair (r + k − 1, c + k − 1) entering and
// (r − 1, c − 1) leaving. Double sums of float products are exact to ~1e-16, so
// (the products are doubles: sliding along 500 diagonal steps costs ~1e-13). Columns
// c ∈ [c_begin, c_end), c_begin ≥ 1, of rows dc sums long.
MARIONETTE_VECTOR_CLONES void slide_window_sums(const TileTerms& m, std::int32_t r, std::int32_t k, std::int32_t dc,
                                                std::int32_t c_begin, std::int32_t c_end, const double* __restrict prev,
                                                double* __restrict cur) {
    const size_t in = m.row_at(static_cast<size_t>(r + k - 1)) + static_cast<size_t>(k - 1);
    const size_t out = m.row_at(static_cast<size_t>(r - 1));
    const size_t n = static_cast<size_t>(dc);
    const double* __restrict dot_in = m.dot + in;
    const double* __restrict dot_out = m.dot + out;
    const double* __restrict cross_in = m.cross + in;
    const double* __restrict cross_out = m.cross + out;
    const double* __restrict y_in = m.y + in;
    const double* __restrict y_out = m.y + out;
    for (size_t c = static_cast<size_t>(c_begin); c < static_cast<size_t>(c_end); ++c) {
        cur[c] = prev[c - 1] + dot_in[c] - dot_out[c - 1];
        cur[n + c] = prev[n + c - 1] + cross_in[c] - cross_out[c - 1];
        cur[2 * n + c] = prev[2 * n + c - 1] + y_in[c] - y_out[c - 1];
    }
    const double ex = m.row_cx[r + k - 1], ez = m.row_cz[r + k - 1], lx = m.row_cx[r - 1], lz = m.row_cz[r - 1];
    const double* __restrict cx_in = m.col_cx + (k - 1);
    const double* __restrict cz_in = m.col_cz + (k - 1);
    const double* __restrict cx_out = m.col_cx;
    const double* __restrict cz_out = m.col_cz;
    for (size_t c = static_cast<size_t>(c_begin); c < static_cast<size_t>(c_end); ++c) {
        cur[3 * n + c] = prev[3 * n + c - 1] + (ex * cx_in[c] + ez * cz_in[c]) - (lx * cx_out[c - 1] + lz * cz_out[c - 1]);
        cur[4 * n + c] = prev[4 * n + c - 1] + (ex * cz_in[c] - ez * cx_in[c]) - (lx * cz_out[c - 1] - lz * cx_out[c - 1]);
    }
}

// The window sums of pair (r, c) summed directly over its k frames.
void direct_window_sums(const TileTerms& m, std::int32_t r, std::int32_t c, std::int32_t k, std::int32_t dc, double* sums) {
    const size_t n = static_cast<size_t>(dc), uc = static_cast<size_t>(c);
    double s[kSumCount] = {};
    for (std::int32_t t = 0; t < k; ++t) {
        const size_t a = static_cast<size_t>(r + t), b = static_cast<size_t>(c + t);
        const size_t at = m.row_at(a) + b;
        s[kSumDot] += m.dot[at];
        s[kSumCross] += m.cross[at];
        s[kSumY] += m.y[at];
        s[kSumCentroidDot] += m.row_cx[a] * m.col_cx[b] + m.row_cz[a] * m.col_cz[b];
        s[kSumCentroidCross] += m.row_cx[a] * m.col_cz[b] - m.row_cz[a] * m.col_cx[b];
    }
    for (int q = 0; q < kSumCount; ++q) sums[static_cast<size_t>(q) * n + uc] = s[q];
}

struct RowWindow {
    double spread;    // Σ w|p − centroid|² of window A
    double sum_x, sum_z;  // Σ_t centroid of window A
};

// Distances of one tile row from its window sums, in double: dot and cross are the
// frames' centred terms plus the centroids' part W·(Σ c_a·c_b − ΣA·ΣB / k);
// D = S_A + S_B − 2Y − 2√(dot² + cross²). Not the value kept: what comes out is the
// interval [lo, hi] (v ∓ bound, through the noise floor, rounded to float) that holds
// the fixed-order kernel's float for the pair, whatever the BLAS kernel's rounding.
// col_x, col_z: W/k · Σ_t centroid of each column's window B. `count` columns from the
// first of each array; the five sums are `stride` apart.
MARIONETTE_VECTOR_CLONES void window_distances(const double* __restrict sums, size_t stride, size_t count, RowWindow a,
                                               double weight,
                                               double inv_wk, double bound, const double* __restrict col_spread,
                                               const double* __restrict col_x, const double* __restrict col_z,
                                               float* __restrict lo_out, float* __restrict hi_out) {
    const size_t n = stride;
    for (size_t c = 0; c < count; ++c) {
        const double dot = sums[c] + (weight * sums[3 * n + c] - (a.sum_x * col_x[c] + a.sum_z * col_z[c]));
        const double cross = sums[n + c] + (weight * sums[4 * n + c] - (a.sum_x * col_z[c] - a.sum_z * col_x[c]));
        const double d = a.spread + col_spread[c] - 2.0 * sums[2 * n + c] - 2.0 * std::sqrt(dot * dot + cross * cross);
        const double v = d * inv_wk;
        const double lo = v - bound, hi = v + bound;
        // (x > floor ? x : +0) as a bit mask, without a branch, so the loop vectorises (the
        // select compiled to a branch and kept it scalar); the same bits as the select.
        const std::uint64_t keep_lo = -static_cast<std::uint64_t>(lo > kDistanceNoiseFloor);
        const std::uint64_t keep_hi = -static_cast<std::uint64_t>(hi > kDistanceNoiseFloor);
        lo_out[c] = static_cast<float>(std::bit_cast<double>(std::bit_cast<std::uint64_t>(lo) & keep_lo));
        hi_out[c] = static_cast<float>(std::bit_cast<double>(std::bit_cast<std::uint64_t>(hi) & keep_hi));
    }
}

// A tile's large scratch arrays, its products' ring (ca, cb, cy: doubles) and both bounds
// of its box (box_lo, box_hi: floats), in one block that grows but is never value-
// initialised: every cell is written (dgemm with beta 0, the distance rows) before it is
// read, and zero-filling them at every size change cost as much as the dgemm. The block is
// 2 MiB-aligned and asks for transparent huge pages (Linux madvise, where the kernel allows
// them): a search's fresh block is then first touched in two 2 MiB pages instead of ~800
// 4 KiB page faults, which were ~40 % of a 1 010-frame search's CPU time (docs/motion-graph.md,
// "Fixed costs"). Only the speed depends on it: no value does.
class TileBuffers {
public:
    double* ca = nullptr;  // per-frame cross terms of the box (dgemm), `ring_cells` each
    double* cb = nullptr;
    double* cy = nullptr;
    float* box_lo = nullptr;  // lower and upper bounds of the box's distances, `box_cells` each
    float* box_hi = nullptr;
    void ensure(size_t ring_cells, size_t box_cells) {
        if (ring_cells <= ring_cells_ && box_cells <= box_cells_) return;
        ring_cells_ = std::max(ring_cells, ring_cells_), box_cells_ = std::max(box_cells, box_cells_);
        constexpr size_t kHugePage = size_t{2} << 20;
        const size_t bytes = 3 * ring_cells_ * sizeof(double) + 2 * box_cells_ * sizeof(float);
        const size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
        block_.reset();
        block_.reset(static_cast<std::byte*>(std::aligned_alloc(kHugePage, rounded)));
        if (!block_) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
        madvise(block_.get(), rounded, MADV_HUGEPAGE);  // advice only: refused, the pages are 4 KiB
#endif
        ca = reinterpret_cast<double*>(block_.get());
        cb = ca + ring_cells_;
        cy = cb + ring_cells_;
        box_lo = reinterpret_cast<float*>(cy + ring_cells_);
        box_hi = box_lo + box_cells_;
    }

private:
    struct Free {
        void operator()(std::byte* p) const { std::free(p); }
    };
    std::unique_ptr<std::byte, Free> block_;
    size_t ring_cells_ = 0, box_cells_ = 0;
};

struct TileScratch {
    TileBuffers buffers;                  // the products' ring and the box's bounds
    std::vector<double> row_cx, row_cz, col_cx, col_cz;  // frame centroids of its rows and columns
    std::vector<double> sums[2];          // window sums of the previous and the current row
    std::vector<double> col_spread, col_x, col_z;  // per column's window B
    std::vector<std::int32_t> invalid_cols;
    std::vector<std::uint8_t> mask;       // a tile line's cells that may be kept
    std::vector<std::pair<std::int32_t, std::int32_t>> cells, sorted;  // a tile's cells that may be kept
    std::vector<size_t> row_start;        // (counting sort of the cells by row)
    std::vector<std::pair<int, int>> undecided;  // neighbours whose order against a cell needs the exact kernel
    std::vector<TransitionCandidate> found;
    std::vector<float> plot;
    std::int64_t evaluations = 0;
    std::int64_t exact_evaluations = 0;
    std::int64_t bound_violations = 0;
};

// Tests only (CandidateSearchOptions::product_noise): every product of a tile moved
// by a pseudo-random amount within ±scale, fixed per (frame pair, product kind).
void perturb_products(double* c, size_t ldc, std::int32_t row0, std::int32_t nr, std::int32_t col0, std::int32_t nc,
                      double scale, std::uint64_t kind) {
    for (std::int32_t r = 0; r < nr; ++r)
        for (std::int32_t q = 0; q < nc; ++q) {
            std::uint64_t x = (static_cast<std::uint64_t>(row0 + r) << 32 | static_cast<std::uint32_t>(col0 + q)) ^ (kind << 62);
            x += 0x9e3779b97f4a7c15ull;  // splitmix64
            x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
            x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
            x ^= x >> 31;
            const double unit = static_cast<double>(x >> 11) * 0x1p-52 - 1.0;  // [−1, 1)
            c[static_cast<size_t>(r) * ldc + static_cast<size_t>(q)] += scale * unit;
        }
}

struct TileSpan {
    std::int32_t ci0, ci1, cj0, cj1;  // the cells this tile decides
    std::int32_t ei0, ei1, ej0, ej1;  // the cells it holds (plus the halo)
    const float* lo = nullptr;        // the held cells' lower bounds, (ei0, ej0) first, i and j steps apart
    size_t lo_i_step = 0, lo_j_step = 1;  // (tile (b, a) reads the box transposed: i step 1)
    const float* hi = nullptr;        // their upper bounds, (ei0, ej0) first, i and j steps apart
    size_t hi_i_step = 0, hi_j_step = 1;
    bool empty() const { return ci0 >= ci1 || cj0 >= cj1; }
};

// The fixed-order kernel's float for a valid pair, checked against the interval the
// tiled pass gave it: outside it, the error bound is wrong, and the build fails.
float exact_distance(const FrameFeatures& f, std::int32_t i, std::int32_t j, float lo, float hi, TileScratch& s) {
    ++s.exact_evaluations;
    const float x = static_cast<float>(feature_pair_distance(f, i, j));
    if (!(x >= lo && x <= hi)) ++s.bound_violations;
    return x;
}

using BridgeLists = std::map<std::pair<std::int32_t, std::int32_t>, std::vector<TransitionCandidate>>;

// A tile's bounds, read with the halo's edges: outside the held cells, absent.
struct TileView {
    const TileSpan& t;
    float lo(std::int32_t i, std::int32_t j) const {
        return i < t.ei0 || i >= t.ei1 || j < t.ej0 || j >= t.ej1 ? kPairInvalid : t.lo[at(i, j)];
    }
    float hi(std::int32_t i, std::int32_t j) const {
        return i < t.ei0 || i >= t.ei1 || j < t.ej0 || j >= t.ej1
                   ? kPairInvalid
                   : t.hi[static_cast<size_t>(i - t.ei0) * t.hi_i_step + static_cast<size_t>(j - t.ej0) * t.hi_j_step];
    }
    // Cell (i, j)'s upper bound in memory, of a held cell or one beside the held cells' edge
    // (along a line: the caller reads only held cells).
    const float* hi_ptr(std::int32_t i, std::int32_t j) const {
        return t.hi + (static_cast<std::ptrdiff_t>(i - t.ei0) * static_cast<std::ptrdiff_t>(t.hi_i_step) +
                       static_cast<std::ptrdiff_t>(j - t.ej0) * static_cast<std::ptrdiff_t>(t.hi_j_step));
    }
    size_t at(std::int32_t i, std::int32_t j) const {
        return static_cast<size_t>(i - t.ei0) * t.lo_i_step + static_cast<size_t>(j - t.ej0) * t.lo_j_step;
    }
};

// Cell (i, j), whose lower bound is at most the keep threshold: a local minimum of the
// exact matrix? Then kept as a candidate (at most the threshold) or a bridge.
void decide_cell(const FrameFeatures& f, const CandidateSearchOptions& o, const TileView& m, std::int32_t i,
                 std::int32_t j, double keep_below, BridgeLists& bridges, TileScratch& s) {
    const std::int32_t h = o.neighbourhood;
    const float lo = m.lo(i, j), hi = m.hi(i, j);
    // Most cells below the threshold lie on a valley's slope: a surely smaller
    // (or excluded) direct neighbour rejects them before the full neighbourhood.
    if (m.hi(i, j - 1) < lo || m.hi(i, j + 1) < lo || m.hi(i - 1, j) < lo || m.hi(i + 1, j) < lo) return;
    if (m.hi(i - 1, j - 1) < lo || m.hi(i + 1, j + 1) < lo || m.hi(i - 1, j + 1) < lo || m.hi(i + 1, j - 1) < lo) return;
    s.undecided.clear();
    for (int di = -h; di <= h; ++di)
        for (int dj = -h; dj <= h; ++dj) {
            if (di == 0 && dj == 0) continue;
            if (m.hi(i + di, j + dj) < lo) return;  // surely smaller, or excluded (−1)
            if (m.lo(i + di, j + dj) <= hi) s.undecided.push_back({di, dj});  // else surely larger, or absent
        }
    const float v = exact_distance(f, i, j, lo, hi, s);
    if (static_cast<double>(v) > keep_below) return;
    for (const auto& [di, dj] : s.undecided) {
        const float ulo = m.lo(i + di, j + dj), uhi = m.hi(i + di, j + dj);
        const float u = ulo == uhi ? ulo : exact_distance(f, i + di, j + dj, ulo, uhi, s);
        if (u < v || (u == v && (di < 0 || (di == 0 && dj < 0)))) return;
    }
    if (v <= o.threshold) {
        s.found.push_back({i, j, v});
        return;
    }
    auto& best = bridges[{f.clip_of[static_cast<size_t>(i)], f.clip_of[static_cast<size_t>(j)]}];
    best.push_back({i, j, v});
    std::sort(best.begin(), best.end(),
              [](const TransitionCandidate& a, const TransitionCandidate& b) { return a.distance < b.distance; });
    if (best.size() > static_cast<size_t>(o.bridges_per_clip_pair)) best.pop_back();
}

// A tile row's valid pairs (counted) and the cells that may be kept (0 ≤ lo ≤ keep_f;
// absent pairs not), a byte each, in one branch-free loop (`&`, not `&&`: it vectorises).
MARIONETTE_VECTOR_CLONES std::int64_t mark_keepable(const float* __restrict row, std::int32_t width, float keep_f,
                                                    std::uint8_t* __restrict mask) {
    std::int64_t evaluated = 0;
    for (std::int32_t c = 0; c < width; ++c) {
        const float v = row[c];
        evaluated += (v >= 0.0f) & (v < kPairInvalid);
        mask[c] = static_cast<std::uint8_t>((v >= 0.0f) & (v <= keep_f));
    }
    return evaluated;
}

// The local minima of the tile's cells, decided on the fixed-order kernel's values.
// The intervals settle most comparisons: a neighbour whose upper bound is below the
// cell's lower bound is smaller whatever the rounding, one whose lower bound is above
// the cell's upper bound larger; the cell's own value and those of neighbours whose
// interval meets it (and is more than one float wide) are computed exactly. So the
// result is the local-minimum rule on the exact matrix, cell for cell.
// Clears mask[q] where a direct neighbour (the 3 × 3 ring) of cell q is surely smaller
// (its upper bound below the cell's lower bound, or excluded: −1): decide_cell's first
// test, on all of a line's marked cells at once and vectorised. hm, h0, hp: the upper
// bounds of the lines before, at and after the cell's, [q − 1, q + 1] readable.
MARIONETTE_VECTOR_CLONES void clear_beaten(const float* __restrict lo, const float* __restrict hm,
                                           const float* __restrict h0, const float* __restrict hp, std::int32_t n,
                                           std::uint8_t* __restrict mask) {
    for (std::int32_t q = 0; q < n; ++q) {
        const float a = std::min(std::min(hm[q - 1], hm[q]), std::min(hm[q + 1], h0[q - 1]));
        const float b = std::min(std::min(h0[q + 1], hp[q - 1]), std::min(hp[q], hp[q + 1]));
        mask[q] = static_cast<std::uint8_t>(mask[q] & static_cast<std::uint8_t>(!(std::min(a, b) < lo[q])));
    }
}

// The tile's cells that may be kept (mark_keepable), as (row, column) offsets from
// (ci0, cj0) in the tile's raster order, into s.cells; counts the valid pairs. The
// lower bounds are scanned along the box's rows: a tile's rows, or for a tile read
// transposed (lo_j_step ≠ 1) its columns, whose marked cells a counting sort then
// puts back into row order (columns ascending within a row, as a row scan gives).
void collect_keepable(const CandidateSearchOptions& o, const TileSpan& t, float keep_f, std::int32_t N, TileScratch& s) {
    const TileView m{t};
    const bool by_rows = t.lo_j_step == 1;
    const std::int32_t rows = t.ci1 - t.ci0, cols = t.cj1 - t.cj0;
    const std::int32_t lines = by_rows ? rows : cols, length = by_rows ? cols : rows;
    s.mask.resize(static_cast<size_t>(length + 8));
    std::uint8_t* __restrict mask = s.mask.data();
    s.cells.clear();
    for (std::int32_t l = 0; l < lines; ++l) {
        const float* __restrict line = t.lo + (by_rows ? m.at(t.ci0 + l, t.cj0) : m.at(t.ci0, t.cj0 + l));
        s.evaluations += mark_keepable(line, length, keep_f, mask);
        // Cells whose 3 × 3 ring lies in the held cells: a surely smaller direct neighbour
        // rules them out here (decide_cell would at its first test; edge cells go there).
        const std::int32_t hl = by_rows ? t.ci0 + l : t.cj0 + l;  // the line's i (rows) or j
        const bool ring_lines = by_rows ? hl > t.ei0 && hl + 1 < t.ei1 : hl > t.ej0 && hl + 1 < t.ej1;
        if (ring_lines) {
            const std::int32_t p0 = by_rows ? t.cj0 : t.ci0, e0 = by_rows ? t.ej0 : t.ei0, e1 = by_rows ? t.ej1 : t.ei1;
            const std::int32_t qa = std::max(0, e0 + 1 - p0), qb = std::min(length, e1 - 1 - p0);
            const auto hi_line = [&](std::int32_t d) {
                return by_rows ? m.hi_ptr(hl + d, p0) : m.hi_ptr(p0, hl + d);
            };
            if (qa < qb)
                clear_beaten(line + qa, hi_line(-1) + qa, hi_line(0) + qa, hi_line(1) + qa, qb - qa, mask + qa);
        }
        if (o.plot)  // (the picture shows the lower bounds: it is not part of the graph)
            for (std::int32_t q = 0; q < length; ++q) {
                const float v = line[q];
                if (!(v >= 0.0f && v < kPairInvalid)) continue;
                const std::int64_t i = t.ci0 + (by_rows ? l : q), j = t.cj0 + (by_rows ? q : l);
                const size_t px = static_cast<size_t>(i * o.plot_size / N), py = static_cast<size_t>(j * o.plot_size / N);
                float& pixel = s.plot[px * static_cast<size_t>(o.plot_size) + py];
                pixel = std::min(pixel, v);
            }
        for (std::int32_t q = length; q % 8 != 0; ++q) mask[q] = 0;
        for (std::int32_t word = 0; word < length; word += 8) {  // eight mask bytes at a time
            std::uint64_t bits;
            std::memcpy(&bits, mask + word, sizeof bits);
            if (bits == 0) continue;
            for (std::int32_t q = word; q < word + 8; ++q)
                if (mask[q]) s.cells.push_back(by_rows ? std::pair{l, q} : std::pair{q, l});
        }
    }
    if (by_rows) return;
    s.row_start.assign(static_cast<size_t>(rows) + 1, 0);
    for (const auto& cell : s.cells) ++s.row_start[static_cast<size_t>(cell.first) + 1];
    for (size_t r = 1; r < s.row_start.size(); ++r) s.row_start[r] += s.row_start[r - 1];
    s.sorted.resize(s.cells.size());
    for (const auto& cell : s.cells) s.sorted[s.row_start[static_cast<size_t>(cell.first)]++] = cell;
    s.cells.swap(s.sorted);
}

// The local minima of the tile's cells, decided on the fixed-order kernel's values.
// The intervals settle most comparisons: a neighbour whose upper bound is below the
// cell's lower bound is smaller whatever the rounding, one whose lower bound is above
// the cell's upper bound larger; the cell's own value and those of neighbours whose
// interval meets it (and is more than one float wide) are computed exactly. So the
// result is the local-minimum rule on the exact matrix, cell for cell.
void decide_tile_minima(const FrameFeatures& f, const CandidateSearchOptions& o, const TileSpan& t, TileScratch& s) {
    const TileView m{t};
    BridgeLists bridges;
    const double keep_below = std::max(o.threshold, o.bridge_threshold);
    // The largest float ≤ keep_below: for a float lo, lo ≤ keep_f ⇔ double(lo) ≤ keep_below.
    float keep_f = static_cast<float>(keep_below);
    if (static_cast<double>(keep_f) > keep_below) keep_f = std::nextafter(keep_f, -std::numeric_limits<float>::infinity());
    collect_keepable(o, t, keep_f, f.frames, s);
    for (const auto& [r, c] : s.cells) decide_cell(f, o, m, t.ci0 + r, t.cj0 + c, keep_below, bridges, s);
    for (const auto& [clips, best] : bridges) s.found.insert(s.found.end(), best.begin(), best.end());
}

// The cells tile [i0, i1) × [j0, j1) decides and the cells it holds (its halo of h).
TileSpan tile_span(const FrameFeatures& f, std::int32_t h, std::int32_t i0, std::int32_t i1, std::int32_t j0,
                   std::int32_t j1) {
    const std::int32_t k = f.window, N = f.frames;
    const std::int32_t i_end = N - k + 1, j_begin = k - 1;  // valid i < i_end, j ≥ j_begin
    TileSpan t{};
    t.ci0 = std::max(i0, 0), t.ci1 = std::min(i1, i_end);
    t.cj0 = std::max(j0, j_begin), t.cj1 = std::min(j1, N);
    if (t.empty()) return t;
    t.ei0 = std::max(t.ci0 - h, 0), t.ei1 = std::min(t.ci1 + h, i_end);
    t.ej0 = std::max(t.cj0 - h, j_begin), t.ej1 = std::min(t.cj1 + h, N);
    return t;
}

// A box whose rows and columns are the same windows (a diagonal tile pair, a = b): row r is
// window A = ei0 + r, column c window B = col0 + c = ei0 − δ + c, so cell (r, c) and cell
// (c − δ, r + δ) hold the same two windows (the window distance is symmetric, and so are
// the pair validity and the near-diagonal exclusion), and both intervals hold the
// fixed-order kernel's float for either (see run_tile_pair). Row r < partial_rows leaves its
// gap [δ, r + δ) to be copied from those mirror cells, computed in earlier rows (column
// r + δ lies in the box); the other rows and the columns [0, δ) (mirrors outside the box)
// are computed. Such a box costs about half of one computed whole.
struct BoxMirror {
    std::int32_t delta = 0;         // ei0 − col0
    std::int32_t partial_rows = 0;  // 0: nothing is mirrored
    std::int32_t strip_products = 0;  // product columns [0, strip_products) the columns [0, δ) read
    std::int32_t gap_begin(std::int32_t r) const { return r < partial_rows ? delta : 0; }
    std::int32_t gap_end(std::int32_t r) const { return r < partial_rows ? r + delta : 0; }
};

BoxMirror box_mirror(bool symmetric, std::int32_t delta, std::int32_t dr, std::int32_t dc, std::int32_t k) {
    BoxMirror m;
    if (!symmetric || delta < 0 || delta >= dc) return m;
    m.delta = delta;
    m.partial_rows = std::min(dr, dc - delta);
    m.strip_products = delta > 0 ? delta + k - 1 : 0;
    return m;
}

// Cells (r, c) of the gap of a mirrored box (BoxMirror) from (c − δ, r + δ), in blocks.
void copy_mirrored(const BoxMirror& m, size_t stride, float* box) {
    constexpr std::int32_t kBlock = 32;
    const std::int32_t rows = m.partial_rows, d = m.delta;
    for (std::int32_t r0 = 0; r0 < rows; r0 += kBlock) {
        const std::int32_t r1 = std::min(r0 + kBlock, rows);
        for (std::int32_t c0 = d; c0 < r1 - 1 + d; c0 += kBlock)
            for (std::int32_t r = r0; r < r1; ++r)
                for (std::int32_t c = c0, c1 = std::min(c0 + kBlock, r + d); c < c1; ++c)
                    box[static_cast<size_t>(r) * stride + static_cast<size_t>(c)] =
                        box[static_cast<size_t>(c - d) * stride + static_cast<size_t>(r + d)];
    }
}

// Product rows per dgemm call (fill_region). 12 000 synthetic frames, CPU seconds of the
// whole build: 32 rows 2.31, 64 2.29, 128 2.25, all rows at once 2.56 (each call repacks
// the columns' operand, so small bands pay that; all at once streams the products through memory).
constexpr std::int32_t kBand = 64;

// The cross terms of a box's frame pairs, C[r][c] = frame (row0 + r) · frame (col0 + c), made
// kBand rows at a time as the rows' sums need them, into a ring of kBand + k rows: what the
// sums read stays in the core's cache instead of streaming megabytes through memory. A
// mirrored box's product row R < partial_rows makes only the columns its rows read,
// [0, strip_products) and [R + δ, nc) (its cells' diagonals stay at or right of c − r = δ).
struct ProductRing {
    const FrameFeatures& f;
    const CandidateSearchOptions& o;
    const DistanceErrorBound& bound;
    const BoxMirror& mirror;
    TileBuffers& b;
    std::int32_t row0, col0, nr, nc, ring;
    std::int32_t made = 0;  // rows [0, made) were made; the ring holds the last `ring` of them

    void columns(std::int32_t first, std::int32_t rows, size_t at, std::int32_t c0, std::int32_t c1) {
        if (c0 >= c1) return;
        const int J = f.joints, width = 2 * J;
        const std::int32_t n = c1 - c0;
        const size_t ucols = static_cast<size_t>(nc), out = at + static_cast<size_t>(c0);
        row_dots(f.xz.data(), row0 + first, rows, f.xz.data(), col0 + c0, n, width, b.ca + out, nc);
        row_dots(f.xz.data(), row0 + first, rows, f.zx.data(), col0 + c0, n, width, b.cb + out, nc);
        row_dots(f.y.data(), row0 + first, rows, f.y.data(), col0 + c0, n, J, b.cy + out, nc);
        if (o.product_noise > 0.0) {
            perturb_products(b.ca + out, ucols, row0 + first, rows, col0 + c0, n, o.product_noise * bound.product_xz, 0);
            perturb_products(b.cb + out, ucols, row0 + first, rows, col0 + c0, n, o.product_noise * bound.product_xz, 1);
            perturb_products(b.cy + out, ucols, row0 + first, rows, col0 + c0, n, o.product_noise * bound.product_y, 2);
        }
    }
    // Rows up to `last` (r + k − 1 for row r, which reads product rows r − 1 … r + k − 1): a band
    // starts at made ≤ last and overwrites rows up to made − ring + kBand − 1 ≤ last − k − 1 = r − 2.
    void through(std::int32_t last) {
        while (made <= last) {
            const std::int32_t slot = made % ring, rows = std::min({kBand, nr - made, ring - slot});
            const size_t at = static_cast<size_t>(slot) * static_cast<size_t>(nc);
            const std::int32_t skip_end = made + mirror.delta;  // the band's first row's first diagonal column
            if (made + rows > mirror.partial_rows || skip_end <= mirror.strip_products) {
                columns(made, rows, at, 0, nc);
            } else {
                columns(made, rows, at, 0, mirror.strip_products);
                columns(made, rows, at, std::min(skip_end, nc), nc);
            }
            made += rows;
        }
    }
};

// Per column of a box: window B's spread and W/k · Σ centroid; columns whose window leaves its clip.
void column_windows(const FrameFeatures& f, std::int32_t ej0, std::int32_t dc, TileScratch& s) {
    const std::int32_t k = f.window, col0 = ej0 - k + 1;
    const size_t udc = static_cast<size_t>(dc);
    s.col_spread.resize(udc);
    s.col_x.resize(udc);
    s.col_z.resize(udc);
    s.invalid_cols.clear();
    const double w_over_k = f.weight / k;
    for (std::int32_t c = 0; c < dc; ++c) {
        const size_t g = static_cast<size_t>(col0 + c);
        s.col_spread[static_cast<size_t>(c)] = f.window_spread[g];
        s.col_x[static_cast<size_t>(c)] = w_over_k * f.window_cx[g];
        s.col_z[static_cast<size_t>(c)] = w_over_k * f.window_cz[g];
        if (!f.end_ok[static_cast<size_t>(ej0 + c)]) s.invalid_cols.push_back(c);
    }
}

// The bounds [lo, hi] of every pair i ∈ [ei0, ei1), j ∈ [ej0, ej1) (valid: i < N − k + 1,
// j ≥ k − 1) into s.buffers.box_lo / box_hi, rows ej1 − ej0 apart: three dgemm products of
// the frames, the window sums slid along the diagonals, the distances in double.
// `symmetric`: the box's rows and columns are the same windows (BoxMirror): about half
// of it is computed, the rest copied.
void fill_region(const FrameFeatures& f, const CandidateSearchOptions& o, const DistanceErrorBound& bound,
                 std::int32_t ei0, std::int32_t ei1, std::int32_t ej0, std::int32_t ej1, bool symmetric, TileScratch& s) {
    const std::int32_t k = f.window;
    const std::int32_t nr = ei1 - ei0 + k - 1, nc = ej1 - ej0 + k - 1;
    const std::int32_t row0 = ei0, col0 = ej0 - k + 1;
    const std::int32_t ring = std::min(nr, kBand + k);
    const size_t ucols = static_cast<size_t>(nc);
    const std::int32_t dr = ei1 - ei0, dc = ej1 - ej0;
    const size_t udc = static_cast<size_t>(dc);
    s.buffers.ensure(static_cast<size_t>(ring) * ucols, static_cast<size_t>(dr) * udc);
    TileBuffers& b = s.buffers;
    const BoxMirror mirror = box_mirror(symmetric, ei0 - col0, dr, dc, k);
    ProductRing products{f, o, bound, mirror, b, row0, col0, nr, nc, ring};

    s.row_cx.assign(f.cx.begin() + row0, f.cx.begin() + row0 + nr);
    s.row_cz.assign(f.cz.begin() + row0, f.cz.begin() + row0 + nr);
    s.col_cx.assign(f.cx.begin() + col0, f.cx.begin() + col0 + nc);
    s.col_cz.assign(f.cz.begin() + col0, f.cz.begin() + col0 + nc);
    const TileTerms terms{b.ca, b.cb, b.cy, s.row_cx.data(), s.row_cz.data(),
                          s.col_cx.data(), s.col_cz.data(), ucols, static_cast<size_t>(ring)};
    column_windows(f, ej0, dc, s);
    // Window sums row by row: row 0 and column 0 directly, the rest by sliding along
    // the diagonals (two double adds per sum and pair instead of k). A mirrored box's first
    // row without a gap after rows with one is summed directly too (its gap's diagonals
    // were not slid).
    s.sums[0].resize(kSumCount * udc);
    s.sums[1].resize(kSumCount * udc);
    const double inv_wk = 1.0 / (f.weight * k);
    for (std::int32_t r = 0; r < dr; ++r) {
        double* cur = s.sums[static_cast<size_t>(r & 1)].data();
        const double* prev = s.sums[static_cast<size_t>((r + 1) & 1)].data();
        products.through(r + k - 1);  // row r's windows end on product row r + k − 1
        const std::int32_t gb = mirror.gap_begin(r), ge = mirror.gap_end(r);  // columns [gb, ge) not computed
        if (r == 0 || (r == mirror.partial_rows && r > 0)) {
            for (std::int32_t c = 0; c < dc; ++c)
                if (c < gb || c >= ge) direct_window_sums(terms, r, c, k, dc, cur);
        } else {
            if (gb > 0 || ge == 0) direct_window_sums(terms, r, 0, k, dc, cur);
            slide_window_sums(terms, r, k, dc, 1, std::max(gb, 1), prev, cur);
            slide_window_sums(terms, r, k, dc, std::max(ge, 1), dc, prev, cur);
        }
        const std::int32_t i = ei0 + r;
        const size_t ui = static_cast<size_t>(i);
        float* __restrict lo = b.box_lo + static_cast<size_t>(r) * udc;
        float* __restrict hi = b.box_hi + static_cast<size_t>(r) * udc;
        if (!f.start_ok[ui]) {
            std::fill(lo, lo + dc, kPairInvalid);
            std::fill(hi, hi + dc, kPairInvalid);
            continue;
        }
        // Branch-free over the row (it vectorises); invalid and near-diagonal pairs
        // are patched afterwards from short lists (their status is exact).
        const RowWindow window{f.window_spread[ui], f.window_cx[ui], f.window_cz[ui]};
        for (const auto& [c0, c1] : {std::pair{0, std::min(gb, dc)}, std::pair{std::max(ge, gb), dc}}) {
            if (c0 >= c1) continue;
            const size_t u0 = static_cast<size_t>(c0);
            window_distances(cur + u0, udc, static_cast<size_t>(c1 - c0), window, f.weight, inv_wk, bound.distance,
                             s.col_spread.data() + u0, s.col_x.data() + u0, s.col_z.data() + u0, lo + u0, hi + u0);
        }
        for (const std::int32_t c : s.invalid_cols) lo[c] = hi[c] = kPairInvalid;  // (gap cells: copied over below)
        // Same clip and windows starting at most k frames apart: g ∈ [i − k, i + k].
        const std::int32_t c_lo = std::max(i - k - col0, 0), c_hi = std::min(i + k - col0, dc - 1);
        for (std::int32_t c = c_lo; c <= c_hi; ++c)
            if ((c < gb || c >= ge) && f.clip_of[static_cast<size_t>(col0 + c)] == f.clip_of[ui] && lo[c] != kPairInvalid)
                lo[c] = hi[c] = kPairExcluded;
    }
    copy_mirrored(mirror, udc, b.box_lo);
    copy_mirrored(mirror, udc, b.box_hi);
}

// Tiles (a, b) and (b, a) from one computed box. The window distance is symmetric: pair
// (i, j) of tile (b, a) (windows starting at i and at g = j − k + 1) is pair
// (g, i + k − 1) of the box, whose interval holds the exact distance of the two
// windows, hence (the bound covers both kernels' errors) the fixed-order kernel's
// float for (i, j) as well. The pair validity and the near-diagonal exclusion are
// symmetric too. So one box of (T + 2h + k − 1)² pairs serves both tiles, instead of
// two of (T + 2h)², and each tile is decided as before, on its own cells.
void run_tile_pair(const FrameFeatures& f, const CandidateSearchOptions& o, const DistanceErrorBound& bound,
                   std::int32_t T, std::int32_t a, std::int32_t b, TileScratch& s) {
    const std::int32_t k = f.window, h = o.neighbourhood;
    TileSpan p = tile_span(f, h, a * T, (a + 1) * T, b * T, (b + 1) * T);
    TileSpan q = a == b ? TileSpan{} : tile_span(f, h, b * T, (b + 1) * T, a * T, (a + 1) * T);
    if (p.empty() && q.empty()) return;
    std::int32_t r0 = std::numeric_limits<std::int32_t>::max(), r1 = std::numeric_limits<std::int32_t>::min();
    std::int32_t c0 = r0, c1 = r1;
    if (!p.empty()) r0 = p.ei0, r1 = p.ei1, c0 = p.ej0, c1 = p.ej1;
    if (!q.empty()) {  // q's cell (i, j) is the box's (j − k + 1, i + k − 1)
        r0 = std::min(r0, q.ej0 - k + 1), r1 = std::max(r1, q.ej1 - k + 1);
        c0 = std::min(c0, q.ei0 + k - 1), c1 = std::max(c1, q.ei1 + k - 1);
    }
    fill_region(f, o, bound, r0, r1, c0, c1, a == b, s);
    const size_t stride = static_cast<size_t>(c1 - c0);
    if (!p.empty()) {
        const size_t at = static_cast<size_t>(p.ei0 - r0) * stride + static_cast<size_t>(p.ej0 - c0);
        p.lo = s.buffers.box_lo + at, p.lo_i_step = stride, p.lo_j_step = 1;
        p.hi = s.buffers.box_hi + at, p.hi_i_step = stride, p.hi_j_step = 1;
        decide_tile_minima(f, o, p, s);
    }
    if (q.empty()) return;
    // q[r][c] = box[c + q.ej0 − k + 1 − r0][r + q.ei0 + k − 1 − c0]: both bounds read in place,
    // transposed (decide_tile_minima scans such a tile along the box's rows).
    const size_t br = static_cast<size_t>(q.ej0 - k + 1 - r0), bc = static_cast<size_t>(q.ei0 + k - 1 - c0);
    q.lo = s.buffers.box_lo + br * stride + bc, q.lo_i_step = 1, q.lo_j_step = stride;
    q.hi = s.buffers.box_hi + br * stride + bc, q.hi_i_step = 1, q.hi_j_step = stride;
    decide_tile_minima(f, o, q, s);
}

}  // namespace

CandidateSearchResult find_transition_candidates(const FrameFeatures& f, const CandidateSearchOptions& o) {
    openblas_set_num_threads(1);  // parallel over tiles instead: one sgemm per thread at a time
    const std::int32_t T = std::max(16, o.tile);
    const std::int32_t tiles_per_side = (f.frames + T - 1) / T;
    // Work items: the tile pairs (a, b), a ≤ b, each one box for tiles (a, b) and (b, a).
    std::vector<std::pair<std::int32_t, std::int32_t>> pairs;
    for (std::int32_t a = 0; a < tiles_per_side; ++a)
        for (std::int32_t b = a; b < tiles_per_side; ++b) pairs.push_back({a, b});
    const std::int64_t tile_count = static_cast<std::int64_t>(pairs.size());
    const int threads = static_cast<int>(std::min<std::int64_t>(thread_count(o.threads), std::max<std::int64_t>(tile_count, 1)));
    // A box's rows (at most T + 2h + k − 1) are slid at most T + 2h + k − 2 times from its
    // directly summed first row.
    const DistanceErrorBound bound = window_distance_error_bound(f, T + 2 * o.neighbourhood + f.window);
    std::vector<TileScratch> scratch(static_cast<size_t>(threads));
    {  // the largest box, once: no reallocation as box sizes vary
        const size_t side = static_cast<size_t>(std::min(T + 2 * o.neighbourhood + f.window - 1, std::max(f.frames, 1)));
        const size_t frames = side + static_cast<size_t>(f.window) - 1;
        const size_t ring = std::min(frames, static_cast<size_t>(kBand + f.window));
        for (TileScratch& s : scratch) {
            s.buffers.ensure(ring * frames, side * side);
        }
    }
    if (o.plot)
        for (TileScratch& s : scratch)
            s.plot.assign(static_cast<size_t>(o.plot_size) * static_cast<size_t>(o.plot_size), kPairInvalid);
    std::atomic<std::int64_t> next{0}, done{0};
    const auto work = [&](int t) {
        for (std::int64_t tile = next++; tile < tile_count; tile = next++) {
            const auto [a, b] = pairs[static_cast<size_t>(tile)];
            run_tile_pair(f, o, bound, T, a, b, scratch[static_cast<size_t>(t)]);
            ++done;
            if (t == 0 && o.progress) o.progress(static_cast<double>(done.load()) / static_cast<double>(tile_count));
        }
    };
    std::vector<std::thread> workers;
    for (int t = 1; t < threads; ++t) workers.emplace_back(work, t);
    work(0);
    for (std::thread& w : workers) w.join();
    if (o.progress) o.progress(1.0);

    CandidateSearchResult out;
    out.distance_bound = bound.distance;
    std::int64_t violations = 0;
    for (TileScratch& s : scratch) {
        out.candidates.insert(out.candidates.end(), s.found.begin(), s.found.end());
        out.pair_evaluations += s.evaluations;
        out.exact_evaluations += s.exact_evaluations;
        violations += s.bound_violations;
    }
    if (violations > 0)  // a bug in window_distance_error_bound, never a property of the data
        throw std::logic_error("transition search: " + std::to_string(violations) +
                               " fixed-order distances fell outside the BLAS pass's error bound");
    std::sort(out.candidates.begin(), out.candidates.end(), [](const TransitionCandidate& a, const TransitionCandidate& b) {
        return a.from_frame != b.from_frame ? a.from_frame < b.from_frame : a.to_frame < b.to_frame;
    });
    if (o.plot) {
        o.plot->assign(static_cast<size_t>(o.plot_size) * static_cast<size_t>(o.plot_size), kPairInvalid);
        for (const TileScratch& s : scratch)
            for (size_t p = 0; p < o.plot->size(); ++p) (*o.plot)[p] = std::min((*o.plot)[p], s.plot[p]);
    }
    return out;
}

CandidateSearchResult find_transition_candidates_reference(const ClipDatabase& db, std::span<const vec3> positions,
                                                           const FrameFeatures& f, double scale,
                                                           const CandidateSearchOptions& o) {
    const std::int32_t N = f.frames;
    std::vector<float> d(static_cast<size_t>(N) * static_cast<size_t>(N));
    CandidateSearchResult out;
    for (std::int32_t i = 0; i < N; ++i)
        for (std::int32_t j = 0; j < N; ++j) {
            float v = pair_status(f, i, j);
            if (v == 0.0f) {
                const double r = reference_pair_distance(db, positions, f.window, scale, i, j);
                v = static_cast<float>(r > kDistanceNoiseFloor ? r : 0.0);
                ++out.pair_evaluations;
            }
            d[static_cast<size_t>(i) * static_cast<size_t>(N) + static_cast<size_t>(j)] = v;
        }
    const auto at = [&](std::int32_t i, std::int32_t j) -> float {
        if (i < 0 || j < 0 || i >= N || j >= N) return kPairInvalid;
        return d[static_cast<size_t>(i) * static_cast<size_t>(N) + static_cast<size_t>(j)];
    };
    for (std::int32_t i = 0; i < N; ++i)
        for (std::int32_t j = 0; j < N; ++j)
            if (is_local_minimum(at(i, j), i, j, o.neighbourhood, o.threshold, at))
                out.candidates.push_back({i, j, at(i, j)});  // regular candidates only
    return out;
}

}  // namespace marionette::offline
