// The gait's costs: two-bone IK per solve, and the whole tick per puppet idle,
// walking and running (on flat ground and on rubble), with how many puppets one
// core ticks at 240 Hz. Flush-to-zero is set as in run and replay.
// Run: build/release/bench/marionette_bench_gait
#include <benchmark/benchmark.h>

#include "bench_rubble.hpp"
#include "runtime/sim/simulation.hpp"
#include "runtime/anim/two_bone_ik.hpp"

using namespace marionette;

namespace {

void BM_TwoBoneIk(benchmark::State& state) {
    set_simulation_float_mode();
    TwoBoneIkResult result;
    TwoBoneIkJob ik;
    ik.root = vec3(0.09f, 0.84f, 0.0f);
    ik.upper_length = 0.44f;
    ik.lower_length = 0.43f;
    ik.result = &result;
    float x = 0.0f;
    for (auto _ : state) {
        x = x > 0.3f ? -0.3f : x + 0.001f;  // a moving target, so nothing is hoisted
        ik.target = vec3(0.09f + 0.1f * x, 0.08f, x);
        if (!ik.run()) state.SkipWithError("TwoBoneIkJob refused its inputs");
        benchmark::DoNotOptimize(result);
    }
    state.counters["ns_per_solve"] =
        benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_TwoBoneIk);

void BM_GaitTick(benchmark::State& state) {
    set_simulation_float_mode();
    const Terrain terrain = state.range(1) ? bench_rubble_terrain() : Terrain{};
    Simulation sim(SimConfig{}, terrain);
    TickInput in;
    in.left_y = static_cast<std::int16_t>(state.range(0));
    std::uint64_t k = 0;
    for (auto _ : state) {
        // Walk back and forth within the terrain: reverse every 4 s.
        if (state.range(0) != 0 && (++k % 960) == 0) in.left_y = static_cast<std::int16_t>(-in.left_y);
        sim.step(in);
        benchmark::DoNotOptimize(sim.state().model_positions[0]);
    }
    const char* gait = state.range(0) == 0 ? "idle" : (state.range(0) < 30000 ? "walk" : "run");
    state.SetLabel(std::string(gait) + (state.range(1) ? " on rubble" : " on flat"));
    state.counters["puppets_at_240Hz_per_core"] =
        benchmark::Counter(static_cast<double>(state.iterations()) / 240.0, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_GaitTick)->Args({0, 0})->Args({20000, 0})->Args({32767, 0})->Args({20000, 1})->Args({32767, 1});

}  // namespace

BENCHMARK_MAIN();
