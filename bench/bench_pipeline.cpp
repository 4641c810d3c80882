// The pipeline's handoffs, measured between real threads (docs/pipeline.md):
//   - SPSC ring throughput (items/s) and one-way latency (half a ping-pong);
//   - triple-buffer handoff latency (half a ping-pong through two buffers);
//   - end to end with the simulated controller at 1 kHz in real time: sample
//     timestamp → the tick that consumed it, p50/p99/max.
// On a shared or two-core machine the latencies measure the scheduler as much as
// the code; pin the threads (taskset) on a quiet machine for the code's own figures.
#include <benchmark/benchmark.h>

#include <atomic>
#include <thread>

#include "app/live/clock.hpp"
#include "app/config/config.hpp"
#include "app/live/pipeline.hpp"
#include "app/config/program_source.hpp"
#include "runtime/handoff/latest_value.hpp"
#include "runtime/handoff/spsc_ring.hpp"

using namespace marionette;

namespace {

void BM_RingThroughput(benchmark::State& state) {
    static SpscRing<std::uint64_t, 4096> ring;
    std::atomic<bool> stop{false};
    std::thread producer([&] {
        std::uint64_t i = 0;
        while (!stop.load(std::memory_order_relaxed))
            if (ring.try_push(i)) ++i;
    });
    constexpr std::uint64_t kBatch = 1 << 16;
    std::uint64_t v = 0, sum = 0;
    for (auto _ : state) {
        for (std::uint64_t n = 0; n < kBatch;)
            if (ring.try_pop(v)) {
                sum += v;
                ++n;
            }
    }
    benchmark::DoNotOptimize(sum);
    stop.store(true);
    producer.join();
    while (ring.try_pop(v)) {
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kBatch));
}
BENCHMARK(BM_RingThroughput)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_RingPingPongLatency(benchmark::State& state) {
    static SpscRing<std::uint64_t, 64> there, back;
    std::atomic<bool> stop{false};
    std::thread echo([&] {
        std::uint64_t v = 0;
        while (!stop.load(std::memory_order_relaxed))
            if (there.try_pop(v))
                while (!back.try_push(v)) {
                }
    });
    std::uint64_t i = 0, v = 0;
    const std::int64_t started = monotonic_ns();
    for (auto _ : state) {
        while (!there.try_push(i)) {
        }
        while (!back.try_pop(v)) {
        }
        ++i;
    }
    stop.store(true);
    echo.join();
    // One iteration is a round trip: the one-way latency is half of it.
    state.counters["one_way_ns"] = static_cast<double>(monotonic_ns() - started) / (2.0 * static_cast<double>(state.iterations()));
}
BENCHMARK(BM_RingPingPongLatency)->UseRealTime()->MinTime(0.5);

void BM_TripleBufferHandoffLatency(benchmark::State& state) {
    static LatestValue<StateFrame> there;  // a full state pair, as the render thread gets it
    static LatestValue<std::uint64_t> back;
    std::atomic<bool> stop{false};
    std::thread reader([&] {
        while (!stop.load(std::memory_order_relaxed))
            if (there.take()) {
                back.back() = there.front().current.tick;
                back.publish();
            }
    });
    std::uint64_t i = 1;
    const std::int64_t started = monotonic_ns();
    for (auto _ : state) {
        StateFrame& f = there.back();
        f.current.tick = i;
        there.publish();
        while (!(back.take() && back.front() == i)) {
        }
        ++i;
    }
    stop.store(true);
    reader.join();
    state.counters["one_way_ns"] = static_cast<double>(monotonic_ns() - started) / (2.0 * static_cast<double>(state.iterations()));
}
BENCHMARK(BM_TripleBufferHandoffLatency)->UseRealTime()->MinTime(0.5);

// The whole pipeline in real time: 1 kHz simulated controller, 240 Hz ticks,
// headless 60 Hz frames, for `seconds` of the demo program.
void BM_EndToEndInputToTick(benchmark::State& state) {
    const double seconds = static_cast<double>(state.range(0));
    const SimConfig config = default_config().sim;
    const StickProgram program = load_program("builtin:demo");
    PipelineResult r;
    for (auto _ : state) {
        PipelineOptions o;
        o.config = config;
        o.script = script_from_program(program, kSimulatedControllerHz);
        o.total_ticks = static_cast<std::uint64_t>(seconds * config.tick_rate_hz);
        o.status_lines = false;
        r = run_pipeline(o);
        state.SetIterationTime(r.wall_s);
    }
    state.counters["p50_us"] = static_cast<double>(r.input_latency.quantile_ns(0.5)) / 1e3;
    state.counters["p99_us"] = static_cast<double>(r.input_latency.quantile_ns(0.99)) / 1e3;
    state.counters["max_us"] = static_cast<double>(r.input_latency.max_ns) / 1e3;
    state.counters["tick_p99_us"] = static_cast<double>(r.tick_time.quantile_ns(0.99)) / 1e3;
    state.counters["samples"] = static_cast<double>(r.input_latency.count);
    state.counters["dropped"] = static_cast<double>(r.samples_dropped);
    state.counters["catch_up_drops"] = static_cast<double>(r.catch_up_drops);
    state.counters["missed_frames"] = static_cast<double>(r.missed_frames);
}
BENCHMARK(BM_EndToEndInputToTick)->Arg(5)->Iterations(1)->UseManualTime()->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
