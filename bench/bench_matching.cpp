// Motion-matching costs (issue 14). Not a test: run by hand.
//   build/release/bench/marionette_bench_matching
// The database is synthetic (tests/runtime/matching/matching_fixture.hpp: clips
// walking at random speeds and curvatures, generated from a fixed seed), 100,000
// frames (MARIONETTE_BENCH_FRAMES to change). Queries are database frames with
// their trajectory features moved, as a stick change moves them (fixed seed).
// Reports, per search: the median, p99 and worst single-query time over 2000
// queries, for the brute-force and the accelerated search, both as wall time
// (µs, steady_clock around each call: inflated by preemption on a loaded
// machine) and as the thread's CPU time (cpu_*_us, CLOCK_THREAD_CPUTIME_ID,
// which a preempted query is not charged for; the clock read adds ~0.3 µs); and the controller's tick (springs, advance, correction, a search every
// search_interval_s, inertialized pose) amortised over the ticks.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <ctime>
#include <vector>

#include "runtime/matching/matching_controller.hpp"
#include "runtime/matching/matching_search.hpp"
#include "tests/runtime/matching/matching_fixture.hpp"

using namespace marionette;

namespace {

double thread_cpu_us() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) * 1e6 + static_cast<double>(t.tv_nsec) * 1e-3;
}

int bench_frames() {
    const char* env = std::getenv("MARIONETTE_BENCH_FRAMES");
    return env ? std::max(1000, std::atoi(env)) : 100000;
}

struct Bench {
    test::MatchingFixture fixture;
    MatchingDatabase db;
    std::vector<std::array<float, kMatchFeatureCount>> queries;
    Bench() : fixture(test::make_matching_fixture(bench_frames() / 400, 400, 17)) {
        if (!build_matching_database(fixture.source(), {}, db).ok()) std::abort();
        std::uint64_t rng = 5;
        for (int q = 0; q < 2000; ++q) {
            std::array<float, kMatchFeatureCount> query{};
            const int frame = static_cast<int>(test::fixture_next(rng) % static_cast<std::uint64_t>(db.frame_count));
            for (int k = 0; k < kMatchFeatureCount; ++k) {
                const float move = k >= kMatchGroupBegin[kMatchTrajectoryPosition] ? static_cast<float>(test::fixture_unit(rng) - 0.5) : 0.0f;
                query[static_cast<size_t>(k)] = db.frame_features(frame)[k] + move;
            }
            queries.push_back(query);
        }
    }
};

const Bench& bench() {
    static const Bench b;
    return b;
}

template <MatchingResult (*Search)(const MatchingDatabase&, std::span<const float>, MatchingResult)>
void search_times(benchmark::State& state) {
    const Bench& b = bench();
    std::vector<double> us, cpu;
    std::int64_t checksum = 0;
    for (auto _ : state) {
        us.clear();
        cpu.clear();
        for (const auto& q : b.queries) {
            const double c0 = thread_cpu_us();
            const auto t0 = std::chrono::steady_clock::now();
            const MatchingResult r = Search(b.db, q, MatchingResult{});
            const auto t1 = std::chrono::steady_clock::now();
            const double c1 = thread_cpu_us();
            checksum += r.frame;
            us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
            cpu.push_back(c1 - c0);
        }
    }
    benchmark::DoNotOptimize(checksum);
    std::sort(us.begin(), us.end());
    std::sort(cpu.begin(), cpu.end());
    state.counters["frames"] = b.db.frame_count;
    state.counters["median_us"] = us[us.size() / 2];
    state.counters["p99_us"] = us[us.size() * 99 / 100];
    state.counters["worst_us"] = us.back();
    state.counters["cpu_median_us"] = cpu[cpu.size() / 2];
    state.counters["cpu_p99_us"] = cpu[cpu.size() * 99 / 100];
    state.counters["cpu_worst_us"] = cpu.back();
}

void BM_SearchBruteForce(benchmark::State& state) { search_times<search_matching_brute_force>(state); }
void BM_SearchAccelerated(benchmark::State& state) { search_times<search_matching_accelerated>(state); }

void BM_ControllerTick(benchmark::State& state) {
    const Bench& b = bench();
    MatchingController mc(b.fixture.source(), b.db, {});
    MatchingState s = mc.initial_state(vec3(0.0f), 0.0f);
    std::array<quat, 7> r{};
    std::array<vec3, 7> t{};
    std::int64_t tick = 0;
    for (auto _ : state) {
        MatchingInput in;
        in.dt = 1.0f / 240.0f;
        const float phase = static_cast<float>(tick % 2400) / 2400.0f;  // a slow circle of changing speed
        in.goal.vx = 1.5f * (phase - 0.5f) * 2.0f;
        in.goal.vz = 1.0f + phase;
        in.goal.heading = phase * 6.0f - 3.0f;
        if (!mc.step(s, in, {r, t})) state.SkipWithError("step failed");
        ++tick;
    }
    state.counters["searches"] = static_cast<double>(s.searches);
    state.counters["jumps"] = static_cast<double>(s.jumps);
}

}  // namespace

BENCHMARK(BM_SearchBruteForce)->Iterations(3)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SearchAccelerated)->Iterations(3)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ControllerTick)->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
