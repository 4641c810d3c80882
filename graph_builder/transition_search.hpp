#pragma once
// Finding transition candidates: Kovar's point-cloud distance between every pair
// of k-frame windows of the database, computed tile by tile so the N×N matrix is
// never held. Per tile, the cross terms of all frame pairs are three dgemm products
// of per-frame feature rows; the k-frame window then becomes a sum sliding
// along the tile's diagonals, and the closed-form 2D alignment turns the sums
// into the minimal distance. Tiles carry a halo of the local-minimum
// neighbourhood, so each tile decides its own local minima.
// BLAS only proposes: each tiled distance comes with a rigorous error bound
// (distance_bound.hpp) against the fixed-order kernel (feature_pair_distance), and
// every decision and every kept distance is the fixed-order kernel's, so the
// candidates are the same bits whichever BLAS kernel, thread count or tile size
// ran (docs/determinism.md, "Graph builds").
#include <cstdint>
#include <functional>
#include <vector>

#include "graph_builder/clip_database.hpp"
#include "runtime/math/planar_alignment.hpp"

namespace marionette::offline {

// Per-frame joint world positions of a database (FK of every frame, root as
// stored), frame-major [frame * joints + joint].
std::vector<vec3> database_positions(const ClipDatabase& db);

// Distances are divided by (Σ weights · k · scale²): a mean squared point distance
// in units of `scale` (the builder uses the leg length), so thresholds do not
// depend on the file's units.
struct FrameFeatures {
    std::int32_t frames = 0;
    std::int32_t joints = 0;
    std::int32_t window = 10;            // k
    double weight = 0.0;                 // Σ w_j
    // Double, not float: the distance is a difference of sums ~1000× larger than
    // itself near the minima, where float products (sgemm) err by more than
    // neighbouring cells differ, and the candidates would follow the rounding.
    std::vector<double> xz;              // [f][2J]: √w(x − cx)…, √w(z − cz)… (c: frame centroid)
    std::vector<double> zx;              // [f][2J]: √w(z − cz)…, −√w(x − cx)…
    std::vector<double> y;               // [f][J]:  √w·y
    std::vector<double> cx, cz;          // weighted ground-plane centroid per frame
    std::vector<double> window_spread;   // per window start: Σ w|p − centroid|² over the window
    std::vector<double> window_cx, window_cz;  // per window start: Σ_t c over the window
    std::vector<std::int32_t> clip_of;   // clip index of every frame
    std::vector<std::uint8_t> start_ok;  // the window starting here stays in one clip
    std::vector<std::uint8_t> end_ok;    // the window ending here stays in one clip
};

FrameFeatures compute_frame_features(const ClipDatabase& db, std::span<const vec3> positions, int window, double scale);

// Pair (i, j): window A = frames i … i+k−1, window B = frames j−k+1 … j.
// +inf when a window leaves its clip; −1 when both windows are in one clip and
// start fewer than k+1 frames apart (the trivial near-diagonal, which no local
// minimum may touch).
inline constexpr float kPairInvalid = 3.0e38f;
// Distances at or below this (normalised: an RMS point distance of 3e-5 leg lengths)
// count as 0 in both searches. Repeats of periodic motion give windows that match to
// the arithmetic's noise (1e-18 … 1e-12, a difference of sums ~1 in double), and
// which of those a local minimum picks would follow the rounding; at 0 the raster
// order decides, the same in both.
inline constexpr double kDistanceNoiseFloor = 1e-9;
inline constexpr float kPairExcluded = -1.0f;

// The same quantity for one pair, straight from the features in double, in one
// fixed order (no BLAS): the value every decision and every stored distance uses
// (the threshold's percentile sample, the candidates' distances).
double feature_pair_distance(const FrameFeatures& f, std::int32_t i, std::int32_t j);

// The straightforward reference: per pair, per window frame, per joint, from the
// positions, with the closed-form alignment. Same normalisation.
double reference_pair_distance(const ClipDatabase& db, std::span<const vec3> positions, int window, double scale,
                               std::int32_t i, std::int32_t j, PlanarTransform* align = nullptr);

// Only the alignment reference_pair_distance computes (the same bits), without the
// distance: what placing a candidate needs.
PlanarTransform reference_pair_alignment(const ClipDatabase& db, std::span<const vec3> positions, int window,
                                         std::int32_t i, std::int32_t j);

struct TransitionCandidate {
    std::int32_t from_frame = 0;  // i (global frame)
    std::int32_t to_frame = 0;    // j (global frame)
    float distance = 0.0f;
};

struct CandidateSearchOptions {
    int neighbourhood = 4;        // local minimum over (2h+1)² cells
    double threshold = 0.0;       // absolute (normalised) distance
    // Minima above the threshold but below this are kept as bridge candidates,
    // only the cheapest few per (source clip, target clip) pair per tile, so
    // memory stays bounded however loose the bridge threshold is.
    double bridge_threshold = 0.0;
    int bridges_per_clip_pair = 4;
    int tile = 512;
    int threads = 0;              // 0: all cores
    std::function<void(double)> progress;  // fraction done, called from the calling thread
    // Optional downsampled image of the matrix (min over each pixel's cells).
    int plot_size = 0;
    std::vector<float>* plot = nullptr;
    // Tests only: moves every dgemm product by up to this fraction of what the error
    // bound allows a BLAS kernel (pseudo-random, fixed per pair), as another kernel's
    // rounding would. The candidates must not change.
    double product_noise = 0.0;
};

struct CandidateSearchResult {
    std::vector<TransitionCandidate> candidates;  // sorted by (from, to)
    std::int64_t pair_evaluations = 0;
    std::int64_t exact_evaluations = 0;  // pairs re-evaluated by the fixed-order kernel
    double distance_bound = 0.0;         // the tiled pass's error bound (normalised distance)
};

CandidateSearchResult find_transition_candidates(const FrameFeatures& features, const CandidateSearchOptions& options);

// The same search, pair by pair with reference_pair_distance (no tiles, no BLAS):
// for benchmarks and tests on small databases.
CandidateSearchResult find_transition_candidates_reference(const ClipDatabase& db, std::span<const vec3> positions,
                                                           const FrameFeatures& features, double scale,
                                                           const CandidateSearchOptions& options);

// The local-minimum rule on a dense row-major matrix (values < 0 mark cells no
// minimum may touch, values ≥ kPairInvalid are absent): cells below the threshold,
// strictly below every earlier neighbour in raster order and not above any later
// one within ±h. The tiled search applies the same rule per tile.
std::vector<std::pair<std::int32_t, std::int32_t>> local_minima(std::span<const float> matrix, std::int32_t rows,
                                                               std::int32_t cols, int h, double threshold);

// Distance at a percentile (0–100) of all valid pairs: exact when there are at
// most `max_samples` pairs, else over a deterministic sample of that many.
// `threads` (0: all cores) only shares the work: the result is the same.
std::vector<double> distance_percentiles(const FrameFeatures& features, const std::vector<double>& percentiles,
                                         std::int64_t max_samples = 65536, int threads = 0);

}  // namespace marionette::offline
