#include "runtime/matching/matching_search.hpp"

#include <array>
#include <cstdint>
#include <cstring>

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

// Lane-parallel float arithmetic in 4-lane vectors (GCC/Clang vector extensions:
// SSE on x86-64, NEON on ARM, plain loops elsewhere). Each lane is ordinary IEEE
// float arithmetic (no contraction: -ffp-contract=off), so a lane's sum is bit
// for bit the scalar sum of the same terms in the same order.
using F4 = float __attribute__((vector_size(16)));
using I4 = std::int32_t __attribute__((vector_size(16)));

F4 load(const float* p) {
    F4 v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
F4 select(I4 mask, F4 a, F4 b) {
    return reinterpret_cast<F4>((mask & reinterpret_cast<I4>(a)) | (~mask & reinterpret_cast<I4>(b)));
}

// Squared distances from the query to L boxes stored feature-major ([k][lane]),
// each lane summed in feature order: each term is at most the same term for any
// frame inside, so (float addition being monotonic) a box's cost never exceeds
// its frames' costs; an empty box (lo = +inf, hi = −inf) costs infinity.
template <size_t L>
std::array<float, L> box_costs(const float* lo, const float* hi, const float* q) {
    constexpr size_t V = L / 4;
    const F4 zero{};
    std::array<F4, V> cost{};
    for (size_t k = 0; k < kMatchFeatureCount; ++k) {
        const F4 qk = zero + q[k];
        for (size_t v = 0; v < V; ++v) {
            const F4 below = load(lo + k * L + 4 * v) - qk;
            const F4 above = qk - load(hi + k * L + 4 * v);
            const F4 d = select(below > 0.0f, below, select(above > 0.0f, above, zero));
            cost[v] += d * d;
        }
    }
    std::array<float, L> out;
    std::memcpy(out.data(), cost.data(), sizeof out);
    return out;
}

struct Search {
    const MatchingDatabase& db;
    const float* q;
    MatchingResult best;

    // The 8 frames of a block: the same terms in the same order as matching_cost,
    // abandoned once every lane is strictly worse than the best (partial sums only grow).
    void block(size_t b) {
        const unsigned mask = db.block_searchable[b];
        if (mask == 0) return;
        const float* x = db.block_features.data() + b * kMatchFeatureCount * kMatchLanes;
        const F4 zero{};
        F4 c0{}, c1{};
        for (size_t k = 0; k < kMatchFeatureCount; ++k) {
            const F4 qk = zero + q[k];
            const F4 d0 = qk - load(x + k * kMatchLanes), d1 = qk - load(x + k * kMatchLanes + 4);
            c0 += d0 * d0;
            c1 += d1 * d1;
            if (k == 8 || k == 17) {
                const I4 worse = (c0 > best.cost) & (c1 > best.cost);
                if (worse[0] && worse[1] && worse[2] && worse[3]) return;
            }
        }
        std::array<float, kMatchLanes> cost;
        std::memcpy(cost.data(), &c0, sizeof c0);
        std::memcpy(cost.data() + 4, &c1, sizeof c1);
        for (int lane = 0; lane < kMatchLanes; ++lane) {
            const std::int32_t f = static_cast<std::int32_t>(b * kMatchLanes) + lane;
            if ((mask >> lane) & 1u && best.beaten_by(cost[static_cast<size_t>(lane)], f)) best = {f, cost[static_cast<size_t>(lane)]};
        }
    }
    void large(size_t l) {
        const size_t stride = kMatchFeatureCount * kMatchSmallPerLarge;
        const auto c = box_costs<kMatchSmallPerLarge>(db.small_lo.data() + l * stride, db.small_hi.data() + l * stride, q);
        for (size_t s = 0; s < kMatchSmallPerLarge; ++s) {
            if (c[s] > best.cost) continue;  // strictly worse: a tie still reaches its frames
            const size_t first = (l * kMatchSmallPerLarge + s) * (kMatchSmallBox / kMatchLanes);
            for (size_t b = first; b < first + kMatchSmallBox / kMatchLanes; ++b) block(b);
        }
    }
    void top(size_t t) {
        const size_t stride = kMatchFeatureCount * kMatchLanes;
        const auto c = box_costs<kMatchLanes>(db.large_lo.data() + t * stride, db.large_hi.data() + t * stride, q);
        for (size_t lane = 0; lane < kMatchLanes; ++lane)
            if (!(c[lane] > best.cost)) large(t * kMatchLanes + lane);
    }
    std::array<float, kMatchLanes> top_costs(size_t group) const {
        const size_t stride = kMatchFeatureCount * kMatchLanes;
        return box_costs<kMatchLanes>(db.top_lo.data() + group * stride, db.top_hi.data() + group * stride, q);
    }
};

}  // namespace

MatchingResult search_matching_accelerated(const MatchingDatabase& db, std::span<const float> query, MatchingResult best) {
    Search s{db, query.data(), best};
    const size_t groups = db.top_lo.size() / (kMatchFeatureCount * kMatchLanes);
    const size_t tops = db.block_features.size() / (static_cast<size_t>(kMatchFeatureCount) * kMatchTopBox);  // the rest pad the last group
    // First the top box nearest the query, for a tight best early; then every
    // other top box in order. The answer is the least (cost, frame) over all
    // searchable frames whatever the visiting order, as a box is skipped only
    // when strictly worse than a cost already found.
    size_t nearest = SIZE_MAX;
    float nearest_cost = std::numeric_limits<float>::infinity();
    for (size_t g = 0; g < groups; ++g) {
        const auto c = s.top_costs(g);
        for (size_t lane = 0; lane < kMatchLanes; ++lane)
            if (g * kMatchLanes + lane < tops && c[lane] < nearest_cost) nearest_cost = c[lane], nearest = g * kMatchLanes + lane;
    }
    if (nearest != SIZE_MAX && !(nearest_cost > s.best.cost)) s.top(nearest);
    for (size_t g = 0; g < groups; ++g) {
        const auto c = s.top_costs(g);
        for (size_t lane = 0; lane < kMatchLanes; ++lane) {
            const size_t t = g * kMatchLanes + lane;
            if (t < tops && t != nearest && !(c[lane] > s.best.cost)) s.top(t);
        }
    }
    return s.best;
}

}  // namespace marionette
