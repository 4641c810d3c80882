// The lock-free primitives and the tick-input assembler, single-threaded: exact
// behaviour at the edges (full, empty, wrap-around, drops, short presses). The
// threaded stress versions are in tests/stress (run under ThreadSanitizer).
#include <catch2/catch.hpp>

#include "runtime/sim/fixed_step.hpp"
#include "runtime/handoff/latency_histogram.hpp"
#include "runtime/handoff/latest_value.hpp"
#include "runtime/handoff/spsc_ring.hpp"
#include "runtime/handoff/tick_input_assembler.hpp"

using namespace marionette;

namespace {
TimedInput sample(std::int64_t t, std::int16_t lx, std::uint32_t buttons = 0) {
    TimedInput s;
    s.timestamp_ns = t;
    s.input.left_x = lx;
    s.input.buttons = buttons;
    return s;
}
}  // namespace

TEST_CASE("ring holds exactly its capacity, refuses more and keeps FIFO order across wrap-around", "[spsc]") {
    SpscRing<int, 8> ring;
    int next_in = 0, next_out = 0;
    for (int round = 0; round < 5; ++round) {  // 5 × 8 items: the indices wrap the slots four times
        while (ring.try_push(next_in)) ++next_in;
        CHECK(next_in - next_out == 8);
        CHECK(ring.size_approx() == 8);
        int v = -1;
        // Take only 5 so the next round starts part-full.
        for (int i = 0; i < 5; ++i) {
            REQUIRE(ring.try_pop(v));
            CHECK(v == next_out++);
        }
    }
    int v = -1;
    while (ring.try_pop(v)) CHECK(v == next_out++);
    CHECK(next_out == next_in);
    CHECK_FALSE(ring.try_pop(v));
    CHECK(ring.peek() == nullptr);
}

TEST_CASE("ring peek shows the oldest item without removing it", "[spsc]") {
    SpscRing<int, 4> ring;
    REQUIRE(ring.try_push(10));
    REQUIRE(ring.try_push(11));
    REQUIRE(ring.peek() != nullptr);
    CHECK(*ring.peek() == 10);
    CHECK(*ring.peek() == 10);
    int v = 0;
    REQUIRE(ring.try_pop(v));
    CHECK(v == 10);
    CHECK(*ring.peek() == 11);
}

TEST_CASE("triple buffer: nothing before the first publish, then always the newest whole value", "[latest]") {
    LatestValue<std::array<int, 4>> buffer;
    CHECK_FALSE(buffer.take());
    buffer.back() = {1, 1, 1, 1};
    buffer.publish();
    buffer.back() = {2, 2, 2, 2};
    buffer.publish();
    REQUIRE(buffer.take());
    CHECK(buffer.front() == std::array<int, 4>{2, 2, 2, 2});  // the older one was overwritten, never mixed
    CHECK_FALSE(buffer.take());                             // nothing newer: front stays as it was
    CHECK(buffer.front()[0] == 2);
    // The writer fills its back buffer while the reader holds front: front does not change.
    buffer.back() = {3, 3, 3, 3};
    CHECK(buffer.front()[0] == 2);
    buffer.publish();
    CHECK(buffer.front()[0] == 2);
    REQUIRE(buffer.take());
    CHECK(buffer.front()[0] == 3);
    CHECK(buffer.published_count() == 3);
}

TEST_CASE("input ring writer drops the newest sample when full and folds its presses into the next", "[assembler]") {
    SpscRing<TimedInput, 2> ring;
    InputRingWriter<SpscRing<TimedInput, 2>> writer(ring);
    CHECK(writer.push(sample(1, 1)));
    CHECK(writer.push(sample(2, 2)));
    CHECK_FALSE(writer.push(sample(3, 3, button_bit(Button::south))));  // full: dropped, press remembered
    CHECK_FALSE(writer.push(sample(4, 4, button_bit(Button::east))));
    CHECK(writer.dropped() == 2);
    TimedInput out;
    REQUIRE(ring.try_pop(out));
    CHECK(writer.push(sample(5, 5)));
    REQUIRE(ring.try_pop(out));
    REQUIRE(ring.try_pop(out));
    CHECK(out.timestamp_ns == 5);
    CHECK(out.input.left_x == 5);
    CHECK(out.input.buttons == (button_bit(Button::south) | button_bit(Button::east)));
    CHECK(writer.pushed() == 3);
    // Once delivered, the folded presses are not repeated.
    CHECK(writer.push(sample(6, 6)));
    REQUIRE(ring.try_pop(out));
    CHECK(out.input.buttons == 0u);
}

TEST_CASE("a disconnect marker is never dropped: it waits and goes in before later samples", "[assembler]") {
    SpscRing<TimedInput, 2> ring;
    InputRingWriter<SpscRing<TimedInput, 2>> writer(ring);
    REQUIRE(writer.push(sample(1, 1)));
    REQUIRE(writer.push(sample(2, 2)));
    writer.push_disconnect(3);  // full: pending
    CHECK_FALSE(writer.push(sample(4, 4)));
    TimedInput out;
    REQUIRE(ring.try_pop(out));
    REQUIRE(ring.try_pop(out));
    CHECK(writer.push(sample(5, 5)));  // the marker first, then this sample
    REQUIRE(ring.try_pop(out));
    CHECK_FALSE(out.connected);
    CHECK(out.timestamp_ns == 3);
    REQUIRE(ring.try_pop(out));
    CHECK(out.connected);
    CHECK(out.timestamp_ns == 5);
}

TEST_CASE("assembler consumes samples up to the tick time: latest sticks, OR of buttons", "[assembler]") {
    SpscRing<TimedInput, 16> ring;
    TickInputAssembler assembler;
    InputLatencyHistogram latency;
    ring.try_push(sample(1'000'000, 100, button_bit(Button::south)));  // a 1 ms press inside the tick
    ring.try_push(sample(2'000'000, 200));
    ring.try_push(sample(3'000'000, 300, button_bit(Button::north)));
    ring.try_push(sample(5'000'000, 500));                              // after the tick: stays queued
    const TickInput a = assembler.assemble(ring, 4'000'000, 4'500'000, latency);
    CHECK(a.left_x == 300);
    CHECK(a.buttons == (button_bit(Button::south) | button_bit(Button::north)));
    CHECK(ring.size_approx() == 1);
    CHECK(latency.count == 3);
    CHECK(latency.max_ns == 3'500'000);  // now − the oldest sample's stamp
    CHECK(latency.sum_ns == 3'500'000 + 2'500'000 + 1'500'000);

    // No sample in the next tick: sticks and held buttons stay as last seen.
    SpscRing<TimedInput, 16> empty;
    const TickInput b = assembler.assemble(empty, 8'000'000, 8'000'000, latency);
    CHECK(b.left_x == 300);
    CHECK(b.buttons == button_bit(Button::north));
}

TEST_CASE("assembler idles the puppet on a disconnect marker and resumes with the next sample", "[assembler]") {
    SpscRing<TimedInput, 16> ring;
    TickInputAssembler assembler;
    InputLatencyHistogram latency;
    ring.try_push(sample(1, 20000, button_bit(Button::west)));
    TimedInput gone;
    gone.timestamp_ns = 2;
    gone.connected = false;
    ring.try_push(gone);
    const TickInput a = assembler.assemble(ring, 10, 10, latency);
    CHECK(a.left_x == 0);                          // idle
    CHECK(a.buttons == button_bit(Button::west));  // the press before the unplug still counts
    CHECK_FALSE(assembler.connected());
    CHECK(assembler.disconnects() == 1);
    const TickInput b = assembler.assemble(ring, 20, 20, latency);
    CHECK(b == TickInput{});
    ring.try_push(sample(25, 12345));
    const TickInput c = assembler.assemble(ring, 30, 30, latency);
    CHECK(c.left_x == 12345);
    CHECK(assembler.connected());
    CHECK(assembler.reconnects() == 1);
    CHECK(latency.count == 2);  // markers are not samples
}

TEST_CASE("duration histogram quantiles are bucket upper edges, capped at the maximum", "[histogram]") {
    DurationHistogram<10, 100> h;
    CHECK(h.quantile_ns(0.5) == 0);
    for (int i = 0; i < 100; ++i) h.add(i * 10 + 5);  // one sample in each bucket
    CHECK(h.count == 100);
    CHECK(h.quantile_ns(0.5) == 500);
    CHECK(h.quantile_ns(0.99) == 990);
    CHECK(h.quantile_ns(1.0) == 995);  // the last edge (1000) is above the maximum
    h.add(1'000'000);                  // beyond the range: the last bucket, exact maximum
    CHECK(h.max_ns == 1'000'000);
    CHECK(h.quantile_ns(1.0) == 1'000'000);
    h.add(-7);                         // clamped, never a negative bucket
    CHECK(h.buckets[0] == 2);
}

TEST_CASE("fixed-step driver runs whole ticks, keeps the remainder and caps the catch-up", "[fixed_step]") {
    FixedStepDriver d = FixedStepDriver::at_rate(250, 4);  // 4 ms ticks
    CHECK(d.advance(3'000'000) == 0);
    CHECK(d.advance(3'000'000) == 1);  // 6 ms: one tick, 2 ms left
    CHECK(d.accumulated_ns == 2'000'000);
    CHECK(d.alpha() == Approx(0.5));
    CHECK(d.advance(100'000'000) == 4);  // 102 ms behind: 4 ticks, the rest dropped and counted
    CHECK(d.catch_up_cap_hits == 1);
    CHECK(d.dropped_ns == 21 * 4'000'000);
    CHECK(d.accumulated_ns == 2'000'000);
}
