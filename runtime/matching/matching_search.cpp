#include "runtime/matching/matching_search.hpp"

namespace marionette {

float matching_cost(const MatchingDatabase& db, std::span<const float> query, int frame) {
    const float* x = db.frame_features(frame);
    float cost = 0.0f;
    for (size_t k = 0; k < kMatchFeatureCount; ++k) {
        const float d = query[k] - x[k];
        cost += d * d;
    }
    return cost;
}

MatchingResult search_matching_brute_force(const MatchingDatabase& db, std::span<const float> query, MatchingResult best) {
    for (int f = 0; f < db.frame_count; ++f) {
        if (!db.searchable[static_cast<size_t>(f)]) continue;
        const float c = matching_cost(db, query, f);
        if (best.beaten_by(c, f)) best = {f, c};
    }
    return best;
}

namespace {

// Squared distance from the query to a box, summed in feature order: each term
// is at most the same term for any frame inside (an empty box, lo = +inf and
// hi = −inf, gives infinity).
float box_cost(const float* lo, const float* hi, const float* q) {
    float cost = 0.0f;
    for (size_t k = 0; k < kMatchFeatureCount; ++k) {
        const float below = lo[k] - q[k];
        const float above = q[k] - hi[k];
        const float d = below > 0.0f ? below : (above > 0.0f ? above : 0.0f);
        cost += d * d;
    }
    return cost;
}

// A frame's cost, abandoned (returning a larger value) once it is strictly worse than `bound`.
float frame_cost_bounded(const float* x, const float* q, float bound) {
    float cost = 0.0f;
    for (size_t k = 0; k < kMatchFeatureCount; ++k) {
        const float d = q[k] - x[k];
        cost += d * d;
        if (cost > bound) return cost;
    }
    return cost;
}

}  // namespace

MatchingResult search_matching_accelerated(const MatchingDatabase& db, std::span<const float> query, MatchingResult best) {
    const float* q = query.data();
    const int frames = db.frame_count;
    for (int large = 0; large * kMatchLargeBox < frames; ++large) {
        const size_t lb = static_cast<size_t>(large) * kMatchFeatureCount;
        if (box_cost(db.large_lo.data() + lb, db.large_hi.data() + lb, q) > best.cost) continue;
        const int small_end = (large + 1) * (kMatchLargeBox / kMatchSmallBox);
        for (int small = large * (kMatchLargeBox / kMatchSmallBox); small < small_end && small * kMatchSmallBox < frames; ++small) {
            const size_t sb = static_cast<size_t>(small) * kMatchFeatureCount;
            if (box_cost(db.small_lo.data() + sb, db.small_hi.data() + sb, q) > best.cost) continue;
            const int end = (small + 1) * kMatchSmallBox < frames ? (small + 1) * kMatchSmallBox : frames;
            for (int f = small * kMatchSmallBox; f < end; ++f) {
                if (!db.searchable[static_cast<size_t>(f)]) continue;
                const float c = frame_cost_bounded(db.frame_features(f), q, best.cost);
                if (best.beaten_by(c, f)) best = {f, c};
            }
        }
    }
    return best;
}

}  // namespace marionette
