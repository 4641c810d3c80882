#pragma once
// The live pipeline's only clock: CLOCK_MONOTONIC in nanoseconds, and absolute
// sleeps on it. Reading it is a vDSO call (no system call on x86-64 and arm64);
// sleeping is clock_nanosleep(TIMER_ABSTIME), the one blocking call a paced
// thread makes, outside its work.
#include <time.h>

#include <atomic>
#include <cerrno>
#include <cstdint>

namespace marionette {

inline std::int64_t monotonic_ns() {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

inline void sleep_until_ns(std::int64_t deadline_ns) {
    timespec ts{};
    ts.tv_sec = static_cast<time_t>(deadline_ns / 1'000'000'000);
    ts.tv_nsec = static_cast<long>(deadline_ns % 1'000'000'000);
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
    }
}

// Sleeps until the deadline in slices of at most 25 ms so a stop request is seen
// promptly; false when stopped before the deadline. (25 ms: longer than a 60 Hz
// frame, so the paced threads wake once per item, not twice.)
inline bool sleep_until_ns_or_stop(std::int64_t deadline_ns, const std::atomic<bool>& stop) {
    constexpr std::int64_t kSliceNs = 25'000'000;
    for (;;) {
        if (stop.load(std::memory_order_relaxed)) return false;
        const std::int64_t now = monotonic_ns();
        if (now >= deadline_ns) return true;
        sleep_until_ns(deadline_ns - now > kSliceNs ? now + kSliceNs : deadline_ns);
    }
}

}  // namespace marionette
