// The gait's costs: two-bone IK per solve, and the whole tick per puppet idle,
// walking and running (on flat ground and on rubble), with how many puppets one
// core ticks at 240 Hz. Flush-to-zero is set as in run and replay.
// Run: build/release/bench/marionette_bench_gait
#include <array>
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

// The same solve four at a time (TwoBoneIkLanesJob: the puppet's two legs and
// two arms, one per lane): ns_per_solve is the time of the four over four.
void BM_TwoBoneIkLanes(benchmark::State& state) {
    set_simulation_float_mode();
    std::array<TwoBoneIkJob, 4> jobs;
    for (std::size_t k = 0; k < jobs.size(); ++k) {
        const float side = k % 2 == 0 ? 1.0f : -1.0f;
        jobs[k].root = k < 2 ? vec3(0.09f * side, 0.84f, 0.0f) : vec3(0.18f * side, 1.38f, 0.0f);
        jobs[k].upper_length = k < 2 ? 0.44f : 0.28f;
        jobs[k].lower_length = k < 2 ? 0.43f : 0.26f;
        jobs[k].pole = k < 2 ? vec3(0.0f, 0.0f, 1.0f) : vec3(0.3f * side, 0.0f, -1.0f);
        jobs[k].hinge_sign = k < 2 ? 1.0f : -1.0f;
    }
    std::array<TwoBoneIkResult, 4> results;
    float x = 0.0f;
    for (auto _ : state) {
        x = x > 0.3f ? -0.3f : x + 0.001f;  // moving targets, so nothing is hoisted
        jobs[0].target = vec3(0.09f + 0.1f * x, 0.08f, x);
        jobs[1].target = vec3(-0.09f - 0.1f * x, 0.08f, -x);
        jobs[2].target = vec3(0.2f, 0.9f, 0.5f * x);
        jobs[3].target = vec3(-0.2f, 0.9f, -0.5f * x);
        if (!TwoBoneIkLanesJob{jobs, results}.run()) state.SkipWithError("TwoBoneIkLanesJob refused its inputs");
        benchmark::DoNotOptimize(results);
    }
    state.counters["ns_per_solve"] = benchmark::Counter(static_cast<double>(state.iterations()) * 4.0,
                                                        benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_TwoBoneIkLanes);

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
