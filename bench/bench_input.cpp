// Input benchmarks: report parse cost per format (ns per report), and sample
// timestamp -> ring delivery latency at simulated 1 kHz and 8 kHz report rates
// (p50/p99/max, as counters). Reports come from firmware_sim.
#include <benchmark/benchmark.h>

#include <time.h>

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

#include "firmware_sim/sim_pad.hpp"
#include "input/calibration.hpp"
#include "input/hid/hid_pad.hpp"
#include "input/input_thread.hpp"

using namespace marionette;
using namespace marionette::input;
namespace fs = marionette::firmware_sim;

namespace {

std::int64_t now_ns() {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

std::vector<fs::Report> make_reports(HidFormat format, bool bluetooth, int rate) {
    const StickProgram p = parse_stick_program(
        "circle 1s radius=1 turns=2\npress south 50ms\nramp 200ms lt=1 rt=0.5 rx=-1\n", "bench.prog");
    fs::SimPadOptions o;
    o.hid_format = format;
    o.rate_hz = rate;
    o.bluetooth = bluetooth;
    o.faults = fs::parse_faults("noise=0.01,seed=1");
    std::vector<fs::Report> out;
    for (const fs::SimFrame& f : fs::simulate_pad(p, o).frames)
        if (f.kind == fs::SimFrame::Kind::report) out.push_back(f.report);
    return out;
}

void BM_Parse(benchmark::State& state, HidFormat format, bool bluetooth) {
    const std::vector<fs::Report> reports = make_reports(format, bluetooth, 1000);
    InputSample s;
    std::size_t i = 0;
    for (auto _ : state) {
        const ParseStatus st = parse_hid_report(format, reports[i].view(), switchpro::kDefaultCalibration, s);
        benchmark::DoNotOptimize(st);
        benchmark::DoNotOptimize(s);
        if (++i == reports.size()) i = 0;
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
BENCHMARK_CAPTURE(BM_Parse, ds4_usb, HidFormat::ds4, false);
BENCHMARK_CAPTURE(BM_Parse, ds4_bluetooth_crc, HidFormat::ds4, true);
BENCHMARK_CAPTURE(BM_Parse, dualsense_usb, HidFormat::dualsense, false);
BENCHMARK_CAPTURE(BM_Parse, dualsense_bluetooth_crc, HidFormat::dualsense, true);
BENCHMARK_CAPTURE(BM_Parse, switchpro, HidFormat::switchpro, false);
BENCHMARK_CAPTURE(BM_Parse, steamdeck, HidFormat::steamdeck, false);

// Parse + calibrate + quantise: everything the input thread does per report
// besides the read itself.
void BM_ParseCalibrateQuantise(benchmark::State& state) {
    const std::vector<fs::Report> reports = make_reports(HidFormat::dualsense, false, 1000);
    FamilyCalibration cal;
    cal.stick_deadzone = 0.07f;
    cal.stick_curve = 1.5f;
    InputSample s;
    std::size_t i = 0;
    for (auto _ : state) {
        parse_hid_report(HidFormat::dualsense, reports[i].view(), switchpro::kDefaultCalibration, s);
        apply_calibration(cal, false, s);
        benchmark::DoNotOptimize(to_timed_input(s));
        if (++i == reports.size()) i = 0;
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
BENCHMARK(BM_ParseCalibrateQuantise);

// A producer thread plays reports at the simulated rate (sleeping to each
// report's deadline on CLOCK_MONOTONIC, as a device's reports arrive), parses,
// stamps, calibrates and pushes each into the SPSC ring; a consumer thread polls
// the ring and records now - timestamp for each sample it pops.
void BM_RingDeliveryLatency(benchmark::State& state) {
    const int rate = static_cast<int>(state.range(0));
    const std::vector<fs::Report> reports = make_reports(HidFormat::dualsense, false, rate);
    const std::size_t n = std::min<std::size_t>(reports.size(), static_cast<std::size_t>(rate) / 2);  // 0.5 s
    std::vector<std::int64_t> latencies;
    latencies.reserve(n * static_cast<std::size_t>(state.max_iterations));
    static InputRing ring;
    for (auto _ : state) {
        std::atomic<bool> done{false};
        std::thread consumer([&] {
            TimedInput t;
            std::size_t got = 0;
            while (got < n) {
                if (ring.try_pop(t)) {
                    latencies.push_back(now_ns() - t.timestamp_ns);
                    ++got;
                } else if (done.load(std::memory_order_acquire) && ring.size_approx() == 0) {
                    break;
                }
            }
        });
        InputRingWriter<InputRing> writer(ring);
        FamilyCalibration cal;
        InputSample s;
        const std::int64_t start = now_ns() + 1'000'000;
        const std::int64_t period = 1'000'000'000 / rate;
        for (std::size_t k = 0; k < n; ++k) {
            const std::int64_t deadline = start + static_cast<std::int64_t>(k) * period;
            timespec ts{static_cast<time_t>(deadline / 1'000'000'000), static_cast<long>(deadline % 1'000'000'000)};
            clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
            parse_hid_report(HidFormat::dualsense, reports[k].view(), switchpro::kDefaultCalibration, s);
            s.t_ns = now_ns();
            apply_calibration(cal, false, s);
            writer.push(to_timed_input(s));
        }
        done.store(true, std::memory_order_release);
        consumer.join();
    }
    std::sort(latencies.begin(), latencies.end());
    const auto q = [&](double f) {
        if (latencies.empty()) return 0.0;
        return static_cast<double>(latencies[static_cast<std::size_t>(f * static_cast<double>(latencies.size() - 1))]) / 1000.0;
    };
    state.counters["p50_us"] = q(0.50);
    state.counters["p99_us"] = q(0.99);
    state.counters["max_us"] = latencies.empty() ? 0.0 : static_cast<double>(latencies.back()) / 1000.0;
    state.counters["samples"] = static_cast<double>(latencies.size());
}
BENCHMARK(BM_RingDeliveryLatency)->Arg(1000)->Arg(8000)->Iterations(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
