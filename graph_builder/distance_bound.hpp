#pragma once
// A rigorous bound on how far the tiled search's distance (dgemm products, window
// sums slid along the tile's diagonals) can lie from the fixed-order kernel's
// (feature_pair_distance: one sequential double sum per pair), whatever order and
// whatever fused or unfused multiply-adds the BLAS kernel uses. The search uses it
// so that BLAS only proposes: every decision and every stored number comes from
// the fixed-order kernel (docs/determinism.md, "Graph builds").
#include <cstdint>

#include "graph_builder/transition_search.hpp"

namespace marionette::offline {

struct DistanceErrorBound {
    // |v_tiled − v_fixed| ≤ distance for every valid pair, v being the normalised
    // distance before the noise floor and the rounding to float (both monotone).
    double distance = 0.0;
    // What the derivation allows one dgemm product to be off by: γ_{2J}·max|xz|²
    // (the dot and cross products) and γ_J·max|y|² (the height products).
    double product_xz = 0.0;
    double product_y = 0.0;
};

// The bound for features `f` searched with tiles whose rows are slid at most
// `max_slides` times from a directly summed first row (tile + 2·halo − 1).
DistanceErrorBound window_distance_error_bound(const FrameFeatures& f, std::int32_t max_slides);

}  // namespace marionette::offline
