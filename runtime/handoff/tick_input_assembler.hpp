#pragma once
// Turns timestamped controller samples into the TickInput of one tick: every
// sample stamped at or before the tick's time is consumed; sticks and triggers
// take the latest sample's values, buttons are the OR of every sample in the
// tick, so a press shorter than a tick is never lost. Runs on the simulation
// thread: no allocation, no clock (the times are handed in).
#include <cstdint>

#include "runtime/handoff/latency_histogram.hpp"
#include "runtime/sim/tick_input.hpp"

namespace marionette {

struct TimedInput {
    std::int64_t timestamp_ns = 0;  // CLOCK_MONOTONIC when the sample was read
    TickInput input{};              // quantised values; buttons held in this sample
    // False marks "the controller is gone" (input is ignored): the puppet idles
    // until a sample with connected = true arrives.
    bool connected = true;
};

// Sample timestamp → the moment the tick that consumed it ran: 10 µs buckets up to 40.96 ms.
using InputLatencyHistogram = DurationHistogram<10'000, 4096>;

// The input thread's side of the ring. When the ring is full the new sample is
// dropped and counted, and its buttons are folded into the next sample that gets
// through, so no press is ever lost. A disconnect marker is never dropped: it
// waits (pending) and goes in before any later sample.
template <typename Ring>
class InputRingWriter {
public:
    explicit InputRingWriter(Ring& ring) : ring_(ring) {}

    bool push(TimedInput sample) {
        if (!flush_pending()) return drop(sample);
        sample.input.buttons |= pending_buttons_;
        if (ring_.try_push(sample)) {
            pending_buttons_ = 0;
            ++pushed_ok_;
            return true;
        }
        return drop(sample);
    }

    // The device is gone: queue a marker stamped `timestamp_ns`.
    void push_disconnect(std::int64_t timestamp_ns) {
        pending_disconnect_ = true;
        pending_disconnect_ns_ = timestamp_ns;
        pending_buttons_ = 0;  // presses of a controller that left are not carried over
        flush_pending();
    }

    // Retries a pending disconnect marker; true when nothing is pending any more.
    bool flush_pending() {
        if (!pending_disconnect_) return true;
        TimedInput marker;
        marker.timestamp_ns = pending_disconnect_ns_;
        marker.connected = false;
        if (!ring_.try_push(marker)) return false;
        pending_disconnect_ = false;
        return true;
    }

    std::uint64_t dropped() const { return dropped_; }
    std::uint64_t pushed() const { return pushed_ok_; }

private:
    bool drop(const TimedInput& sample) {
        ++dropped_;
        pending_buttons_ |= sample.input.buttons;
        return false;
    }

    Ring& ring_;
    std::uint32_t pending_buttons_ = 0;
    std::uint64_t dropped_ = 0;
    std::uint64_t pushed_ok_ = 0;
    bool pending_disconnect_ = false;
    std::int64_t pending_disconnect_ns_ = 0;
};

class TickInputAssembler {
public:
    // Consumes every sample stamped ≤ tick_time_ns. `now_ns` is when the tick
    // runs: each consumed sample adds now_ns − timestamp to `latency`.
    // Ring: anything with `const TimedInput* peek()` and `bool try_pop(TimedInput&)`.
    template <typename Ring>
    TickInput assemble(Ring& ring, std::int64_t tick_time_ns, std::int64_t now_ns, InputLatencyHistogram& latency) {
        std::uint32_t buttons = 0;
        bool any = false;
        last_samples_ = 0;
        while (const TimedInput* next = ring.peek()) {
            if (next->timestamp_ns > tick_time_ns) break;
            TimedInput sample;
            ring.try_pop(sample);
            if (!sample.connected) {
                if (connected_) ++disconnects_;
                connected_ = false;
                latest_ = TickInput{};
                continue;  // presses already seen in this tick stay in `buttons`
            }
            if (!connected_) ++reconnects_;
            connected_ = true;
            latest_ = sample.input;
            buttons |= sample.input.buttons;
            any = true;
            latency.add(now_ns - sample.timestamp_ns);
            if (last_samples_++ == 0) last_oldest_ns_ = sample.timestamp_ns;
            last_newest_ns_ = sample.timestamp_ns;
        }
        TickInput out = latest_;
        // With no new sample the last state holds: buttons still held stay held.
        out.buttons = any ? buttons : (buttons | latest_.buttons);
        return out;
    }

    bool connected() const { return connected_; }
    // The samples the last assemble() consumed (disconnect markers aside), and
    // the stamps of its oldest and newest (valid when the count is > 0).
    std::uint32_t last_samples() const { return last_samples_; }
    std::int64_t last_oldest_ns() const { return last_oldest_ns_; }
    std::int64_t last_newest_ns() const { return last_newest_ns_; }
    std::uint64_t disconnects() const { return disconnects_; }
    std::uint64_t reconnects() const { return reconnects_; }

private:
    TickInput latest_{};
    bool connected_ = true;
    std::uint32_t last_samples_ = 0;
    std::int64_t last_oldest_ns_ = 0;
    std::int64_t last_newest_ns_ = 0;
    std::uint64_t disconnects_ = 0;
    std::uint64_t reconnects_ = 0;
};

}  // namespace marionette
