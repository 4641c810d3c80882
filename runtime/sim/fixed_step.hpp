#pragma once
// The real-time side of the fixed timestep: a driver is handed elapsed time (it
// never reads a clock itself) and says how many whole ticks to run. When the
// simulation falls behind by more than the catch-up cap it drops the backlog and
// counts it, rather than spiralling. Replay does not use this: it runs ticks with
// no clock at all.
#include <cstdint>

namespace marionette {

struct FixedStepDriver {
    std::int64_t tick_ns = 0;            // duration of one tick
    std::int32_t max_catch_up_ticks = 8; // most ticks run for one advance()
    std::int64_t accumulated_ns = 0;
    std::uint64_t catch_up_cap_hits = 0; // times the backlog was dropped
    std::int64_t dropped_ns = 0;

    static FixedStepDriver at_rate(std::int32_t tick_rate_hz, std::int32_t max_catch_up_ticks) {
        FixedStepDriver d;
        d.tick_ns = 1'000'000'000 / tick_rate_hz;
        d.max_catch_up_ticks = max_catch_up_ticks;
        return d;
    }

    // Adds elapsed wall time; returns how many ticks to run now.
    std::int32_t advance(std::int64_t elapsed_ns) {
        if (elapsed_ns > 0) accumulated_ns += elapsed_ns;
        std::int64_t ticks = accumulated_ns / tick_ns;
        if (ticks > max_catch_up_ticks) {
            ++catch_up_cap_hits;
            dropped_ns += (ticks - max_catch_up_ticks) * tick_ns;
            ticks = max_catch_up_ticks;
            accumulated_ns = ticks * tick_ns + accumulated_ns % tick_ns;
        }
        accumulated_ns -= ticks * tick_ns;
        return static_cast<std::int32_t>(ticks);
    }

    // Fraction of a tick elapsed since the last tick ran: the render interpolation alpha.
    double alpha() const { return static_cast<double>(accumulated_ns) / static_cast<double>(tick_ns); }
};

}  // namespace marionette
