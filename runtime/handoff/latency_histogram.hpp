#pragma once
// A fixed-size histogram of durations (latencies, tick and frame times): adding
// is a few integer operations and never allocates, so the real-time threads keep
// one each and the report reads quantiles after they are joined.
#include <array>
#include <cstdint>

namespace marionette {

template <std::int64_t BucketNs, int Buckets>
struct DurationHistogram {
    static constexpr std::int64_t kBucketNs = BucketNs;
    static constexpr int kBuckets = Buckets;

    std::uint64_t count = 0;
    std::int64_t max_ns = 0;
    std::int64_t sum_ns = 0;
    // Bucket b holds [b·BucketNs, (b+1)·BucketNs); the last one holds the rest.
    std::array<std::uint32_t, Buckets> buckets{};

    void add(std::int64_t ns) {
        if (ns < 0) ns = 0;  // clocks of two threads: never negative by construction, but be safe
        ++count;
        sum_ns += ns;
        if (ns > max_ns) max_ns = ns;
        std::int64_t b = ns / BucketNs;
        if (b >= Buckets) b = Buckets - 1;
        ++buckets[static_cast<std::size_t>(b)];
    }

    // Upper edge of the bucket holding the q-quantile (0..1), in ns; never above max_ns.
    std::int64_t quantile_ns(double q) const {
        if (count == 0) return 0;
        const auto target = static_cast<std::uint64_t>(q * static_cast<double>(count - 1)) + 1;
        std::uint64_t seen = 0;
        for (int b = 0; b < Buckets; ++b) {
            seen += buckets[static_cast<std::size_t>(b)];
            if (seen >= target) {
                if (b == Buckets - 1) return max_ns;  // the overflow bucket has no upper edge
                const std::int64_t edge = (b + 1) * BucketNs;
                return edge < max_ns ? edge : max_ns;
            }
        }
        return max_ns;
    }
    std::int64_t mean_ns() const { return count == 0 ? 0 : sum_ns / static_cast<std::int64_t>(count); }
};

}  // namespace marionette
