#include "runtime/matching/matching_search.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#if defined(__SSE__)
#include <xmmintrin.h>
#endif

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
#if !defined(__SSE__)
F4 select(I4 mask, F4 a, F4 b) {
    return reinterpret_cast<F4>((mask & reinterpret_cast<I4>(a)) | (~mask & reinterpret_cast<I4>(b)));
}
#endif

// Squared distances from the query to L boxes stored feature-major ([k][lane]),
// each lane summed over features [Begin, kMatchFeatureCount) in feature order.
// Each term is at most the same term for any frame inside, and float addition is
// monotonic and never decreases a sum by a non-negative term, so such a sum
// (the whole of it, or only the later features, the trajectory, which tell clips
// apart the most) never exceeds a frame's matching_cost: a box whose sum is
// strictly worse than the best holds no frame that could win or tie. An empty
// box (lo = +inf, hi = −inf) costs infinity for a finite query.
constexpr size_t kTrajectoryBegin = static_cast<size_t>(kMatchGroupBegin[kMatchTrajectoryPosition]);

// One feature's term for 4 boxes: the square of how far the query is below lo or
// above hi (0 inside). For finite bounds with lo ≤ hi this is max(below, above,
// 0) exactly; either form is at most the term of any frame inside, which is all
// the search needs (an empty box may read 0 instead of +inf when the query is
// infinite: a weaker bound, still a bound; a NaN query reads 0, as the frames'
// NaN costs never win anyway).
F4 box_term(const float* lo, const float* hi, F4 qk) {
    const F4 below = load(lo) - qk;
    const F4 above = qk - load(hi);
#if defined(__SSE__)
    const F4 d = _mm_max_ps(_mm_max_ps(below, above), F4{});
#else
    const F4 zero{};
    const F4 d = select(below > 0.0f, below, select(above > 0.0f, above, zero));
#endif
    return d * d;
}

template <size_t L, size_t Begin = 0>
std::array<float, L> box_costs(const float* lo, const float* hi, const float* q) {
    static_assert(L == 4 || L == 8);
    const F4 zero{};
    F4 c0{}, c1{};
    for (size_t k = Begin; k < kMatchFeatureCount; ++k) {
        const F4 qk = zero + q[k];
        c0 += box_term(lo + k * L, hi + k * L, qk);
        if constexpr (L == 8) c1 += box_term(lo + k * L + 4, hi + k * L + 4, qk);
    }
    std::array<float, L> out;
    std::memcpy(out.data(), &c0, sizeof c0);
    if constexpr (L == 8) std::memcpy(out.data() + 4, &c1, sizeof c1);
    return out;
}

template <size_t N>
bool all_worse(const std::array<float, N>& c, float bound) {
    bool all = true;
    for (float x : c) all = all && x > bound;
    return all;
}

// Lanes 0..N−1 by increasing cost (insertion sort; any order is exact, nearer first prunes more).
template <size_t N>
std::array<std::uint8_t, N> by_cost(const std::array<float, N>& c) {
    std::array<std::uint8_t, N> order;
    for (size_t i = 0; i < N; ++i) {
        size_t j = i;
        for (; j > 0 && c[i] < c[order[j - 1]]; --j) order[j] = order[j - 1];
        order[j] = static_cast<std::uint8_t>(i);
    }
    return order;
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
            const std::int32_t f = db.block_frame[b * kMatchLanes + static_cast<size_t>(lane)];
            if ((mask >> lane) & 1u && best.beaten_by(cost[static_cast<size_t>(lane)], f)) best = {f, cost[static_cast<size_t>(lane)]};
        }
    }
    void large(size_t l) {
        const size_t stride = kMatchFeatureCount * kMatchSmallPerLarge;
        const float* lo = db.small_lo.data() + l * stride;
        const float* hi = db.small_hi.data() + l * stride;
        if (all_worse(box_costs<kMatchSmallPerLarge, kTrajectoryBegin>(lo, hi, q), best.cost)) return;
        const auto c = box_costs<kMatchSmallPerLarge>(lo, hi, q);
        for (const std::uint8_t s : by_cost(c)) {
            if (c[s] > best.cost) continue;  // strictly worse: a tie still reaches its frames
            const size_t first = (l * kMatchSmallPerLarge + s) * (kMatchSmallBox / kMatchLanes);
            for (size_t b = first; b < first + kMatchSmallBox / kMatchLanes; ++b) block(b);
        }
    }
    void top(size_t t) {
        const size_t stride = kMatchFeatureCount * kMatchLanes;
        const float* lo = db.large_lo.data() + t * stride;
        const float* hi = db.large_hi.data() + t * stride;
        const auto c = box_costs<kMatchLanes>(lo, hi, q);
        for (const std::uint8_t lane : by_cost(c))
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
    const size_t tops = db.block_features.size() / (static_cast<size_t>(kMatchFeatureCount) * kMatchTopBox);  // the rest pad the last group
    // Top boxes a chunk at a time (costs on the stack): the few nearest the query
    // first, for a tight best early, then the others in order. The answer is the
    // least (cost, frame) over all searchable frames whatever the visiting order,
    // as a box is skipped only when strictly worse than a cost already found.
    constexpr size_t kChunk = 256;      // top boxes per chunk (131,072 frames)
    constexpr int kNearestFirst = 4;
    std::array<float, kChunk> cost;
    std::array<bool, kChunk> done;
    for (size_t first = 0; first < tops; first += kChunk) {
        const size_t n = tops - first < kChunk ? tops - first : kChunk;
        for (size_t g = 0; g * kMatchLanes < n; ++g) {
            const auto c = s.top_costs(first / kMatchLanes + g);
            std::memcpy(cost.data() + g * kMatchLanes, c.data(), sizeof c);
        }
        std::fill(done.begin(), done.begin() + static_cast<std::ptrdiff_t>(n), false);
        for (int pass = 0; pass < kNearestFirst; ++pass) {
            size_t nearest = n;
            for (size_t i = 0; i < n; ++i)
                if (!done[i] && (nearest == n || cost[i] < cost[nearest])) nearest = i;
            if (nearest == n || cost[nearest] > s.best.cost) break;
            done[nearest] = true;
            s.top(first + nearest);
        }
        for (size_t i = 0; i < n; ++i)
            if (!done[i] && !(cost[i] > s.best.cost)) s.top(first + i);
    }
    return s.best;
}

}  // namespace marionette
