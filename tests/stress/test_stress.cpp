// Stress tests of the lock-free handoffs between real threads, meant to run under
// ThreadSanitizer (`tsan` preset; scripts/test.sh runs only this target there):
// millions of items, asserting order, no loss beyond counted drops, and no torn
// values. Item counts scale with MARIONETTE_STRESS_SCALE (default 1).
#include <catch2/catch.hpp>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <thread>
#include <vector>

#include "runtime/handoff/latest_value.hpp"
#include "runtime/handoff/spsc_ring.hpp"
#include "runtime/handoff/tick_input_assembler.hpp"

using namespace marionette;

namespace {
std::uint64_t scaled(std::uint64_t n) {
    const char* env = std::getenv("MARIONETTE_STRESS_SCALE");
    const double scale = env ? std::atof(env) : 1.0;
    return static_cast<std::uint64_t>(static_cast<double>(n) * (scale > 0.0 ? scale : 1.0));
}

// A payload whose every word derives from its sequence number: any mix of two
// writes (a torn read) breaks the relation.
struct Stamped {
    std::uint64_t seq = 0;
    std::uint64_t words[30] = {};
    void fill(std::uint64_t s) {
        seq = s;
        for (std::uint64_t i = 0; i < 30; ++i) words[i] = s * 0x9E3779B97F4A7C15ull + i;
    }
    bool intact() const {
        for (std::uint64_t i = 0; i < 30; ++i)
            if (words[i] != seq * 0x9E3779B97F4A7C15ull + i) return false;
        return true;
    }
};
}  // namespace

TEST_CASE("ring delivers millions of items in order with nothing lost", "[stress]") {
    const std::uint64_t count = scaled(4'000'000);
    SpscRing<std::uint64_t, 1024> ring;
    std::thread producer([&] {
        for (std::uint64_t i = 0; i < count;)
            if (ring.try_push(i)) ++i;
            else std::this_thread::yield();
    });
    std::uint64_t expected = 0, out_of_order = 0, v = 0;
    while (expected < count) {
        if (!ring.try_pop(v)) {
            std::this_thread::yield();
            continue;
        }
        if (v != expected) ++out_of_order;
        expected = v + 1;
    }
    producer.join();
    CHECK(out_of_order == 0);
    CHECK(expected == count);
    CHECK_FALSE(ring.try_pop(v));
}

TEST_CASE("ring of large items never shows a torn item", "[stress]") {
    const std::uint64_t count = scaled(1'000'000);
    SpscRing<Stamped, 64> ring;
    std::thread producer([&] {
        Stamped s;
        for (std::uint64_t i = 0; i < count;) {
            s.fill(i);
            if (ring.try_push(s)) ++i;
            else std::this_thread::yield();
        }
    });
    std::uint64_t next = 0, torn = 0, wrong = 0;
    Stamped s;
    while (next < count) {
        // Consume through peek() as the assembler does, then pop.
        const Stamped* p = ring.peek();
        if (!p) {
            std::this_thread::yield();
            continue;
        }
        if (!p->intact()) ++torn;
        if (!ring.try_pop(s)) ++wrong;  // peek saw it, so pop must get it
        if (!s.intact()) ++torn;
        if (s.seq != next) ++wrong;
        next = s.seq + 1;
    }
    producer.join();
    CHECK(torn == 0);
    CHECK(wrong == 0);
}

TEST_CASE("input ring under overload drops only what it counts and loses no press", "[stress]") {
    // The producer never waits (like the input thread); the consumer is slowed so
    // the ring overflows often. Sample i carries press bit (i % 15) when i % 7 == 0.
    const std::uint64_t count = scaled(2'000'000);
    using Ring = SpscRing<TimedInput, 256>;
    Ring ring;
    std::atomic<bool> done{false};
    std::uint64_t dropped = 0, pushed = 0;
    std::thread producer([&] {
        InputRingWriter<Ring> writer(ring);
        for (std::uint64_t i = 0; i < count; ++i) {
            TimedInput s;
            s.timestamp_ns = static_cast<std::int64_t>(i);
            s.input.left_x = static_cast<std::int16_t>(i & 0x7fff);
            if (i % 7 == 0) s.input.buttons = 1u << (i % 15);
            writer.push(s);
        }
        // The last sample must get through, so pending presses are delivered.
        TimedInput last;
        last.timestamp_ns = static_cast<std::int64_t>(count);
        while (!writer.push(last)) std::this_thread::yield();
        dropped = writer.dropped();  // every failed push, including the final retries
        pushed = writer.pushed();
        done.store(true, std::memory_order_release);
    });
    std::vector<TimedInput> received;
    received.reserve(static_cast<size_t>(count) + 1);
    TimedInput s;
    std::uint64_t spin = 0;
    for (;;) {
        if (ring.try_pop(s)) {
            received.push_back(s);
            // Stall now and then, as a descheduled simulation thread would: the ring overflows.
            if ((++spin & 4095) == 0) std::this_thread::sleep_for(std::chrono::microseconds(100));
            continue;
        }
        if (done.load(std::memory_order_acquire)) {
            while (ring.try_pop(s)) received.push_back(s);
            break;
        }
        std::this_thread::yield();
    }
    producer.join();
    INFO("received " << received.size() << ", dropped " << dropped);
    // count + 1 pushes attempted, plus the final retries (counted as drops of the same sample).
    CHECK(received.back().timestamp_ns == static_cast<std::int64_t>(count));
    std::uint64_t out_of_order = 0, torn = 0;
    for (size_t i = 1; i < received.size(); ++i)
        if (received[i].timestamp_ns <= received[i - 1].timestamp_ns) ++out_of_order;
    for (const TimedInput& r : received)
        if (r.timestamp_ns < static_cast<std::int64_t>(count) && r.input.left_x != static_cast<std::int16_t>(r.timestamp_ns & 0x7fff))
            ++torn;
    CHECK(out_of_order == 0);
    CHECK(torn == 0);
    // Each press is delivered by the first received sample at or after it.
    std::uint64_t lost_presses = 0;
    size_t j = 0;
    for (std::uint64_t i = 0; i < count; i += 7) {
        while (j < received.size() && received[j].timestamp_ns < static_cast<std::int64_t>(i)) ++j;
        if (j == received.size() || !(received[j].input.buttons & (1u << (i % 15)))) ++lost_presses;
    }
    CHECK(lost_presses == 0);
    // Every sample that got in came out; every one that did not was counted.
    CHECK(received.size() == pushed);
    CHECK(count + 1 - pushed <= dropped);
    CHECK(dropped > 0);  // the overload really happened
}

TEST_CASE("triple buffer hands over a million values, newest first, never torn", "[stress]") {
    const std::uint64_t count = scaled(1'000'000);
    LatestValue<Stamped> buffer;
    std::atomic<bool> done{false};
    std::thread writer([&] {
        for (std::uint64_t i = 1; i <= count; ++i) {
            buffer.back().fill(i);
            buffer.publish();
        }
        done.store(true, std::memory_order_release);
    });
    std::uint64_t last = 0, taken = 0, torn = 0, backwards = 0;
    for (;;) {
        const bool finished = done.load(std::memory_order_acquire);
        if (buffer.take()) {
            const Stamped& s = buffer.front();
            if (!s.intact()) ++torn;
            if (s.seq <= last) ++backwards;
            last = s.seq;
            ++taken;
            continue;
        }
        if (finished) break;  // nothing fresh after the writer's last publish: we have seen it
    }
    writer.join();
    INFO("taken " << taken << " of " << count);
    CHECK(torn == 0);
    CHECK(backwards == 0);
    CHECK(last == count);  // the final value is always delivered
    CHECK(taken > 0);
}
