#pragma once
// Turns timestamped controller samples into the TickInput of one tick: every
// sample stamped at or before the tick's time is consumed; sticks and triggers
// take the latest sample's values, buttons are the OR of every sample in the
// tick, so a press shorter than a tick is never lost. Runs on the simulation
// thread: no allocation, no clock (the tick time is handed in).
#include <cstdint>

#include "runtime/tick_input.hpp"

namespace marionette {

struct TimedInput {
    std::int64_t timestamp_ns = 0;  // CLOCK_MONOTONIC when the sample was read
    TickInput input{};              // quantised values; buttons held in this sample
};

struct AssemblerStats {
    std::uint64_t samples = 0;
    // Latency from a sample's timestamp to the tick that consumed it.
    std::int64_t latency_max_ns = 0;
    std::int64_t latency_sum_ns = 0;
    // Histogram in 100 µs buckets up to 25.6 ms (the last bucket holds the rest).
    static constexpr int kBuckets = 256;
    static constexpr std::int64_t kBucketNs = 100'000;
    std::uint32_t histogram[kBuckets] = {};

    void add(std::int64_t latency_ns) {
        ++samples;
        latency_sum_ns += latency_ns;
        if (latency_ns > latency_max_ns) latency_max_ns = latency_ns;
        std::int64_t bucket = latency_ns < 0 ? 0 : latency_ns / kBucketNs;
        if (bucket >= kBuckets) bucket = kBuckets - 1;
        ++histogram[bucket];
    }
    // Upper edge of the bucket holding the q-quantile (0..1), in ns.
    std::int64_t quantile_ns(double q) const {
        if (samples == 0) return 0;
        const auto target = static_cast<std::uint64_t>(q * static_cast<double>(samples - 1)) + 1;
        std::uint64_t seen = 0;
        for (int b = 0; b < kBuckets; ++b) {
            seen += histogram[b];
            if (seen >= target) return (b + 1) * kBucketNs;
        }
        return kBuckets * kBucketNs;
    }
};

// The input thread's side of the ring: when the ring is full the new sample is
// dropped and counted, and its buttons are folded into the next sample that gets
// through, so no press is ever lost.
template <typename Ring>
class InputRingWriter {
public:
    explicit InputRingWriter(Ring& ring) : ring_(ring) {}
    bool push(TimedInput sample) {
        sample.input.buttons |= pending_buttons_;
        if (ring_.try_push(sample)) {
            pending_buttons_ = 0;
            return true;
        }
        ++dropped_;
        pending_buttons_ |= sample.input.buttons;
        return false;
    }
    std::uint64_t dropped() const { return dropped_; }

private:
    Ring& ring_;
    std::uint32_t pending_buttons_ = 0;
    std::uint64_t dropped_ = 0;
};

class TickInputAssembler {
public:
    // Ring: anything with `const TimedInput* peek()` and `bool try_pop(TimedInput&)`.
    template <typename Ring>
    TickInput assemble(Ring& ring, std::int64_t tick_time_ns, AssemblerStats& stats) {
        std::uint32_t buttons = 0;
        bool any = false;
        while (const TimedInput* next = ring.peek()) {
            if (next->timestamp_ns > tick_time_ns) break;
            TimedInput sample;
            ring.try_pop(sample);
            latest_ = sample.input;
            buttons |= sample.input.buttons;
            any = true;
            stats.add(tick_time_ns - sample.timestamp_ns);
        }
        TickInput out = latest_;
        // With no new sample the last state holds: buttons still held stay held.
        out.buttons = any ? buttons : latest_.buttons;
        return out;
    }

    // Device gone: the puppet idles until a controller returns.
    void reset() { latest_ = TickInput{}; }

private:
    TickInput latest_{};
};

}  // namespace marionette
