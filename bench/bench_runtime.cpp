// Runtime core costs: forward kinematics per joint, one simulation tick of the
// default puppet, the state hash, and input-log encode/decode throughput.
// Run: build/release/bench/marionette_bench_runtime
#include <benchmark/benchmark.h>

#include "runtime/anim/local_to_model.hpp"
#include "runtime/formats/input_log.hpp"
#include "runtime/gait/puppet.hpp"
#include "runtime/sim/simulation.hpp"

using namespace marionette;

namespace {

// Arg 1: with the skeleton's FkSchedule (two joints per vector where the CPU
// has AVX2: the tick's path); arg 0: without (one joint per vector).
void BM_LocalToModel(benchmark::State& state) {
    set_simulation_float_mode();
    const SimConfig config;
    const Skeleton skeleton = make_puppet_skeleton(config);
    const Clip walk = make_walk_clip(skeleton, config);
    const FkSchedule schedule(skeleton.parents);
    const size_t n = static_cast<size_t>(skeleton.joint_count());
    std::vector<quat> mr(n);
    std::vector<vec3> mp(n);
    const LocalToModelJob job{skeleton.parents,
                              {std::span<const quat>(walk.frame_rotations(10), n),
                               std::span<const vec3>(walk.frame_translations(10), n)},
                              {mr, mp},
                              state.range(0) != 0 ? &schedule : nullptr};
    for (auto _ : state) {
        if (!job.run()) state.SkipWithError("LocalToModelJob refused its inputs");
        benchmark::DoNotOptimize(mp.data());
        benchmark::ClobberMemory();
    }
    state.SetLabel(state.range(0) == 0 ? "one joint per vector"
                                       : (fk::pairs_kernel_available() ? "two joints per vector (AVX2)"
                                                                       : "schedule given, no AVX2: one joint per vector"));
    state.counters["ns_per_joint"] =
        benchmark::Counter(static_cast<double>(state.iterations() * n), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_LocalToModel)->Arg(1)->Arg(0);

void BM_SimulationTick(benchmark::State& state) {
    set_simulation_float_mode();
    Simulation sim{SimConfig{}};
    TickInput in;
    in.left_y = static_cast<std::int16_t>(state.range(0));
    for (auto _ : state) {
        sim.step(in);
        benchmark::DoNotOptimize(sim.state().model_positions[0]);
    }
    state.SetLabel(state.range(0) == 0 ? "idle" : "walking");
    state.counters["puppets_at_240Hz_per_core"] = benchmark::Counter(
        static_cast<double>(state.iterations()) / 240.0, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SimulationTick)->Arg(0)->Arg(20000);

void BM_HashState(benchmark::State& state) {
    Simulation sim{SimConfig{}};
    sim.step(TickInput{});
    for (auto _ : state) benchmark::DoNotOptimize(hash_state(sim.state()));
}
BENCHMARK(BM_HashState);

void BM_InputLogEncodeDecode(benchmark::State& state) {
    std::vector<TickInput> ticks(240 * 60);
    for (size_t k = 0; k < ticks.size(); ++k) {
        ticks[k].left_x = static_cast<std::int16_t>((k / 7) % 2000);
        ticks[k].buttons = (k % 97 == 0) ? 1u : 0u;
    }
    InputLogHeader header;
    size_t bytes = 0;
    for (auto _ : state) {
        const std::vector<std::uint8_t> log = encode_input_log(header, ticks, 60);
        const DecodedInputLog decoded = decode_input_log(log, "bench");
        bytes = log.size();
        benchmark::DoNotOptimize(decoded.ticks.data());
    }
    state.counters["ticks_per_s"] = benchmark::Counter(static_cast<double>(state.iterations() * ticks.size()),
                                                       benchmark::Counter::kIsRate);
    state.counters["log_bytes_per_minute"] = static_cast<double>(bytes);
}
BENCHMARK(BM_InputLogEncodeDecode);

}  // namespace

BENCHMARK_MAIN();
