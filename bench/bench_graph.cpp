// Motion-graph build and query costs (issue 4). Not a test: run by hand.
//   build/release/bench/marionette_bench_graph
// MARIONETTE_MOCAP_DIR (default ../shared/data/mocap) holds the CMU clips;
// MARIONETTE_BENCH_FRAMES sets the synthetic database size (default 100000).
// `--benchmark_filter=Controller` runs only the controller (circle, and circle
// with action presses on the default graph and CMU-16).
// Reports, per build: seconds, pair evaluations per second, peak RSS; for the
// reference comparison: both times, the speed-up and whether the candidates agree.
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdlib>
#include <random>

#include "app/graph/default_graph.hpp"
#include "graph_builder/distance_bound.hpp"
#include "graph_builder/graph_builder.hpp"
#include "runtime/math/det_math.hpp"
#include "runtime/graph/graph_controller.hpp"
#include "runtime/graph/graph_path.hpp"

using namespace marionette;
using namespace marionette::offline;

namespace {

std::string mocap_dir() {
    const char* env = std::getenv("MARIONETTE_MOCAP_DIR");
    return env && *env ? env : MARIONETTE_DEFAULT_MOCAP_DIR;
}

// CPU seconds of the whole process: with other work on the machine, wall time
// over-states single-threaded costs; the speed-up ratio uses CPU time.
double process_cpu_s() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double peak_rss_mb() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

LabelRules cmu_labels() {
    LabelRules rules;
    rules.origin = "bench";
    rules.clip_patterns = {{"16_1*", {"walk"}}, {"16_33", {"walk", "stop"}}, {"16_35", {"run"}}, {"16_4*", {"run", "turn"}},
                           {"16_57", {"run", "stop"}}};
    return rules;
}

const ClipDatabase& cmu16() {
    static const ClipDatabase db = [] {
        std::vector<std::string> files;
        for (const char* c : {"16_11", "16_15", "16_17", "16_19", "16_33", "16_35", "16_41", "16_43", "16_57"})
            files.push_back(mocap_dir() + "/cmu_amc_16/" + c + ".amc");
        return load_clip_database(files, mocap_dir() + "/cmu_amc_16/16.asf", cmu_labels(), 30.0);
    }();
    return db;
}

// The shared clips repeated until `frames`, each copy perturbed: every joint
// rotation turned by up to ~2° about a random axis that drifts smoothly, and the
// root moved and turned, so copies are similar but never identical.
ClipDatabase synthetic(std::int64_t frames) {
    const ClipDatabase& base = cmu16();
    std::vector<Clip> clips;
    std::mt19937 rng(1234);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::int64_t total = 0;
    for (int copy = 0; total < frames; ++copy)
        for (const Clip& source : base.clips) {
            if (total >= frames) break;
            Clip c = source;
            c.name = source.name + "_" + std::to_string(copy);
            const int J = c.joint_count();
            std::vector<vec3> axis(static_cast<size_t>(J));
            for (vec3& a : axis) a = glm::normalize(vec3(u(rng), u(rng), u(rng)) + vec3(0.01f));
            const PlanarTransform place{u(rng) * 3.0, u(rng) * 100.0, u(rng) * 100.0};
            for (int f = 0; f < c.frame_count; ++f)
                for (int j = 0; j < J; ++j) {
                    const size_t at = static_cast<size_t>(f) * static_cast<size_t>(J) + static_cast<size_t>(j);
                    const double angle = 0.035 * std::sin(0.1 * f + j + copy);
                    c.rotations[at] = quat_normalize(quat_mul(c.rotations[at], quat_axis_angle(axis[static_cast<size_t>(j)], angle)));
                    if (j == 0) {
                        c.rotations[at] = quat_mul(planar_rotation(place), c.rotations[at]);
                        c.translations[at] = apply_planar(place, c.translations[at]);
                    }
                }
            total += c.frame_count;
            clips.push_back(std::move(c));
        }
    return make_clip_database(std::move(clips), {}, cmu_labels(), 30.0);
}

void report_build(benchmark::State& state, const GraphBuildOutput& out, double seconds) {
    const double n = static_cast<double>(out.frames);
    state.counters["frames"] = n;
    state.counters["seconds"] = seconds;
    state.counters["pair_evals_per_s"] = static_cast<double>(out.graph.stats.pair_evaluations) / seconds;
    state.counters["candidates"] = static_cast<double>(out.regular_candidates);
    state.counters["bridges"] = static_cast<double>(out.bridges);
    state.counters["nodes_before"] = static_cast<double>(out.prune.nodes_before);
    state.counters["nodes"] = static_cast<double>(out.prune.nodes);
    state.counters["edges"] = static_cast<double>(out.prune.edges);
    state.counters["kept_pct"] = 100.0 * static_cast<double>(out.graph.stats.frames_kept) / n;
    state.counters["peak_rss_mb"] = peak_rss_mb();
}

void BM_BuildCmu16(benchmark::State& state) {
    const ClipDatabase& db = cmu16();
    for (auto _ : state) {
        const auto t0 = std::chrono::steady_clock::now();
        const GraphBuildOutput out = build_motion_graph(db, GraphBuildParams{});
        report_build(state, out, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
}

void BM_BuildSynthetic(benchmark::State& state) {
    const char* env = std::getenv("MARIONETTE_BENCH_FRAMES");
    const std::int64_t frames = env ? std::atoll(env) : 100000;
    const ClipDatabase db = synthetic(frames);
    for (auto _ : state) {
        const auto t0 = std::chrono::steady_clock::now();
        const double c0 = process_cpu_s();
        GraphBuildParams params;
        params.bridge_percentile = params.threshold_percentile;  // no bridges: the copies connect by themselves
        const GraphBuildOutput out = build_motion_graph(db, params);
        report_build(state, out, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        state.counters["cpu_s"] = process_cpu_s() - c0;
    }
}

// The subset BM_ReferenceSpeedup and BM_TiledSearch search: a synthetic database
// of `frames` frames, its features, and one-thread search options at its 5th
// percentile distance.
struct SubsetSearch {
    ClipDatabase db;
    double leg;
    std::vector<vec3> p;
    FrameFeatures f;
    CandidateSearchOptions o;
};

SubsetSearch subset_search(std::int64_t frames) {
    SubsetSearch s{synthetic(frames), 0.0, {}, {}, {}};
    s.leg = skeleton_leg_length(s.db.skeleton, s.db.left_foot);
    s.p = database_positions(s.db);
    s.f = compute_frame_features(s.db, s.p, 10, s.leg);
    s.o.neighbourhood = 4;
    s.o.threshold = distance_percentiles(s.f, {5.0})[0];
    s.o.threads = 1;
    return s;
}

// The straightforward reference (per pair, per window frame, per joint) against
// the tiled search on a subset, both on one thread. The tiled search's time is the
// median of five complete calls (each allocating its buffers afresh), the
// reference's one call (seconds). The candidate sets must be identical: any
// difference fails the benchmark. Sizes 1000, 2000 and 3000 frames show how the
// speed-up grows as the tiled search's fixed costs are spread (the reference's
// time grows with the pairs: ~2, 8 and 18 s of CPU).
void BM_ReferenceSpeedup(benchmark::State& state) {
    const SubsetSearch subset = subset_search(static_cast<std::int64_t>(state.range(0)));
    const ClipDatabase& db = subset.db;
    const double leg = subset.leg;
    const std::vector<vec3>& p = subset.p;
    const FrameFeatures& f = subset.f;
    const CandidateSearchOptions& o = subset.o;
    for (auto _ : state) {
        std::vector<double> cpu, wall;
        CandidateSearchResult tiled;
        for (int run = 0; run < 5; ++run) {
            const double c0 = process_cpu_s();
            const auto t0 = std::chrono::steady_clock::now();
            tiled = find_transition_candidates(f, o);
            wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
            cpu.push_back(process_cpu_s() - c0);
        }
        std::sort(cpu.begin(), cpu.end());
        std::sort(wall.begin(), wall.end());
        const double c1 = process_cpu_s();
        const auto t1 = std::chrono::steady_clock::now();
        const CandidateSearchResult ref = find_transition_candidates_reference(db, p, f, leg, o);
        const double rs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
        const double rc = process_cpu_s() - c1;
        const double tc = cpu[2], ts = wall[2];
        state.counters["tiled_cpu_s"] = tc;
        state.counters["reference_cpu_s"] = rc;
        state.counters["speedup_cpu"] = rc / tc;
        size_t same = 0;
        for (size_t a = 0, b = 0; a < tiled.candidates.size() && b < ref.candidates.size();) {
            const auto& x = tiled.candidates[a];
            const auto& y = ref.candidates[b];
            if (x.from_frame == y.from_frame && x.to_frame == y.to_frame) ++same, ++a, ++b;
            else if (std::make_pair(x.from_frame, x.to_frame) < std::make_pair(y.from_frame, y.to_frame)) ++a;
            else ++b;
        }
        const bool identical = same == ref.candidates.size() && same == tiled.candidates.size() &&
                               tiled.pair_evaluations == ref.pair_evaluations;
        state.counters["frames"] = static_cast<double>(f.frames);
        state.counters["pairs"] = static_cast<double>(ref.pair_evaluations);
        state.counters["tiled_s"] = ts;
        state.counters["reference_s"] = rs;
        state.counters["speedup"] = rs / ts;
        state.counters["tiled_candidates"] = static_cast<double>(tiled.candidates.size());
        state.counters["exact_evals"] = static_cast<double>(tiled.exact_evaluations);  // fixed-order re-evaluations
        state.counters["bound"] = tiled.distance_bound;
        state.counters["threshold"] = o.threshold;
        state.counters["reference_candidates"] = static_cast<double>(ref.candidates.size());
        state.counters["same_candidates"] = static_cast<double>(same);
        state.counters["identical"] = identical ? 1.0 : 0.0;
        if (!identical) state.SkipWithError("the tiled search and the reference give different candidates");
    }
}

// The tiled search alone, one thread, on BM_ReferenceSpeedup's database: a narrow
// driver to profile (`perf record` with --benchmark_filter=TiledSearch). Each call
// allocates its buffers afresh, as a build does.
void BM_TiledSearch(benchmark::State& state) {
    const SubsetSearch subset = subset_search(static_cast<std::int64_t>(state.range(0)));
    std::size_t candidates = 0;
    for (auto _ : state) candidates = find_transition_candidates(subset.f, subset.o).candidates.size();
    state.counters["candidates"] = static_cast<double>(candidates);
}

void BM_PathQuery(benchmark::State& state) {
    static const GraphBuildOutput out = build_motion_graph(cmu16(), GraphBuildParams{});
    const MotionGraph& g = out.graph;
    GraphPathSearch search(g, 1.0);
    std::mt19937 rng(5);
    std::vector<double> micros;
    for (auto _ : state) {
        state.PauseTiming();
        search.clear_goals();
        search.add_label_goal(static_cast<int>(rng() % g.labels.size()));
        const int start = static_cast<int>(rng() % g.nodes.size());
        state.ResumeTiming();
        const auto t0 = std::chrono::steady_clock::now();
        benchmark::DoNotOptimize(search.run(start));
        micros.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
    }
    std::sort(micros.begin(), micros.end());
    state.counters["median_us"] = micros[micros.size() / 2];
    state.counters["p99_us"] = micros[micros.size() * 99 / 100];
    state.counters["max_us"] = micros.back();
}

// The graph controller on the CMU-16 graph following a circle program (stick
// direction turning at 0.5 rad/s) at 60 Hz: cost per tick, median, p99 and max.
void BM_ControllerCircleCmu16(benchmark::State& state) {
    static const GraphBuildOutput out = build_motion_graph(cmu16(), GraphBuildParams{});
    const MotionGraph& g = out.graph;
    GraphControllerConfig config;
    config.max_speed = 1.5 * g.leg_length;
    config.max_nodes_per_tick = static_cast<int>(state.range(0));
    GraphController controller(g, config);
    GraphControllerState s = controller.initial_state();
    std::vector<quat> r(static_cast<size_t>(g.joint_count()));
    std::vector<vec3> t(static_cast<size_t>(g.joint_count()));
    std::vector<double> micros;
    micros.reserve(1 << 20);
    std::int64_t tick = 0;
    for (auto _ : state) {
        GraphControllerInput in;
        in.dt = 1.0f / 60.0f;
        const double a = 0.5 * static_cast<double>(tick++) / 60.0;
        in.stick_x = static_cast<float>(det::sin(a));
        in.stick_y = static_cast<float>(-det::cos(a));
        const auto t0 = std::chrono::steady_clock::now();
        if (!controller.step(s, in, {r, t})) {
            state.SkipWithError("the graph controller refused its pose spans");
            break;
        }
        micros.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
        benchmark::DoNotOptimize(r.data());
    }
    std::sort(micros.begin(), micros.end());
    state.counters["median_us"] = micros[micros.size() / 2];
    state.counters["p99_us"] = micros[micros.size() * 99 / 100];
    state.counters["max_us"] = micros.back();
    state.counters["nodes_per_tick"] = static_cast<double>(s.nodes_expanded) / static_cast<double>(tick);
    state.counters["transitions"] = static_cast<double>(s.transitions_taken);
}

// The controller following the same circle while the face buttons south, east,
// west, north are pressed in turn every 3 s (100 ms each), at the simulation's
// 240 Hz: every tick, and separately the ticks where an action path query was
// being sliced (mode find_action, or the tick that finished it).
void controller_circle_actions(benchmark::State& state, const MotionGraph& g) {
    GraphControllerConfig config;
    config.max_speed = 1.5 * g.leg_length;
    config.max_nodes_per_tick = static_cast<int>(state.range(0));
    const char* const labels[4] = {"jump", "wave", "bow", "look_around"};
    const char* const fallback[4] = {"walk", "run", "turn", "stop"};  // CMU-16 has no action clips
    for (int b = 0; b < 4; ++b) {
        const int l = g.label_index(labels[b]);
        config.button_label[static_cast<size_t>(b)] = l >= 0 ? l : g.label_index(fallback[b]);
    }
    GraphController controller(g, config);
    GraphControllerState s = controller.initial_state();
    std::vector<quat> r(static_cast<size_t>(g.joint_count()));
    std::vector<vec3> t(static_cast<size_t>(g.joint_count()));
    std::vector<double> micros, query_micros;
    micros.reserve(1 << 20), query_micros.reserve(1 << 20);
    std::int64_t tick = 0, presses = 0;
    constexpr int kHz = 240;
    for (auto _ : state) {
        GraphControllerInput in;
        in.dt = 1.0f / kHz;
        const double a = 0.5 * static_cast<double>(tick) / kHz;
        in.stick_x = static_cast<float>(det::sin(a));
        in.stick_y = static_cast<float>(-det::cos(a));
        const std::int64_t phase = tick % (3 * kHz);
        if (phase >= kHz && phase < kHz + kHz / 10) in.buttons = static_cast<std::uint16_t>(1u << ((tick / (3 * kHz)) % 4));
        presses += phase == kHz;
        ++tick;
        const bool querying = s.mode == GraphMotionMode::find_action || (in.buttons != 0 && s.mode == GraphMotionMode::locomotion);
        const auto t0 = std::chrono::steady_clock::now();
        if (!controller.step(s, in, {r, t})) {
            state.SkipWithError("the graph controller refused its pose spans");
            break;
        }
        const double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
        micros.push_back(us);
        if (querying) query_micros.push_back(us);
        benchmark::DoNotOptimize(r.data());
    }
    std::sort(micros.begin(), micros.end());
    std::sort(query_micros.begin(), query_micros.end());
    state.counters["median_us"] = micros[micros.size() / 2];
    state.counters["p99_us"] = micros[micros.size() * 99 / 100];
    state.counters["max_us"] = micros.back();
    if (!query_micros.empty()) {
        state.counters["query_ticks"] = static_cast<double>(query_micros.size());
        state.counters["query_median_us"] = query_micros[query_micros.size() / 2];
        state.counters["query_max_us"] = query_micros.back();
    }
    state.counters["presses"] = static_cast<double>(presses);
    state.counters["actions_played"] = static_cast<double>(s.actions_played);
    state.counters["transitions"] = static_cast<double>(s.transitions_taken);
}

void BM_ControllerCircleActionsCmu16(benchmark::State& state) {
    static const GraphBuildOutput out = build_motion_graph(cmu16(), GraphBuildParams{});
    controller_circle_actions(state, out.graph);
}

void BM_ControllerCircleActionsDefault(benchmark::State& state) {
    static const MotionGraph g = build_default_motion_graph(SimConfig{}, GraphBuildConfig{});
    controller_circle_actions(state, g);
}

// A study, not a speed figure (docs/motion-graph.md, "A float proposal pass, measured"):
// what a float (sgemm) proposal pass or block culling could save, on the dense
// fixed-order matrix of the synthetic database (range(0) frames, threshold the 5th
// percentile, h = 4). `float_bound` is a first-order estimate of a float pass's error
// bound (γ per product at u = 2⁻²⁴, operands' rounding, ×2), not a proof; the counters
// `exact_<b>` count the fixed-order re-evaluations decide_cell would need with intervals
// ±b (the 8e-12 row is today's double pass), `blocks<B>` the share of B×B blocks holding
// a cell at most threshold + float_bound (blocks a culling pass could not skip).
void BM_FloatProposalStudy(benchmark::State& state) {
    const ClipDatabase db = synthetic(state.range(0));
    const double leg = skeleton_leg_length(db.skeleton, db.left_foot);
    const FrameFeatures f = compute_frame_features(db, database_positions(db), 10, leg);
    const double thr = distance_percentiles(f, {5.0})[0];
    const int N = f.frames, J = f.joints, h = 4;
    std::vector<float> d(static_cast<size_t>(N) * static_cast<size_t>(N));
    for (auto _ : state) {
        for (int i = 0; i < N; ++i)
            for (int j = 0; j < N; ++j) d[static_cast<size_t>(i) * static_cast<size_t>(N) + static_cast<size_t>(j)] = static_cast<float>(feature_pair_distance(f, i, j));
        double rx2 = 0.0, ry2 = 0.0;
        for (size_t fr = 0; fr < static_cast<size_t>(N); ++fr) {
            double x = 0.0, y = 0.0;
            for (size_t q = 0; q < 2 * static_cast<size_t>(J); ++q) x += f.xz[fr * 2 * J + q] * f.xz[fr * 2 * J + q];
            for (size_t q = 0; q < static_cast<size_t>(J); ++q) y += f.y[fr * J + q] * f.y[fr * J + q];
            rx2 = std::max(rx2, x), ry2 = std::max(ry2, y);
        }
        const double uf = 0x1p-24;
        const double float_bound = 2.0 * (4.0 * (2 * J + 2) * uf * rx2 + 2.0 * (J + 2) * uf * ry2) / f.weight;
        const auto at = [&](int i, int j) -> double {
            return i < 0 || j < 0 || i >= N || j >= N ? kPairInvalid : d[static_cast<size_t>(i) * static_cast<size_t>(N) + static_cast<size_t>(j)];
        };
        const auto floor0 = [](double v) { return v > kDistanceNoiseFloor ? v : 0.0; };
        for (const double b : {8e-12, float_bound}) {
            std::int64_t exact = 0;
            const auto lo = [&](int i, int j) { const double v = at(i, j); return v < 0.0 || v >= kPairInvalid ? v : floor0(v - b); };
            const auto hi = [&](int i, int j) { const double v = at(i, j); return v < 0.0 || v >= kPairInvalid ? v : floor0(v + b); };
            for (int i = 0; i < N; ++i)
                for (int j = 0; j < N; ++j) {
                    const double l = lo(i, j), hc = hi(i, j);
                    if (!(l >= 0.0 && l <= thr)) continue;
                    std::int64_t undecided = 0;
                    bool rejected = false;
                    for (int di = -h; di <= h && !rejected; ++di)
                        for (int dj = -h; dj <= h; ++dj) {
                            if (di == 0 && dj == 0) continue;
                            if (hi(i + di, j + dj) < l) { rejected = true; break; }
                            if (lo(i + di, j + dj) <= hc && lo(i + di, j + dj) != hi(i + di, j + dj)) ++undecided;
                        }
                    if (rejected) continue;
                    exact += 1 + (at(i, j) <= thr ? undecided : 0);
                }
            state.counters[b == 8e-12 ? "exact_double" : "exact_float"] = static_cast<double>(exact);
        }
        for (const int B : {8, 16, 32, 64, 128, 512}) {
            std::int64_t blocks = 0, needed = 0;
            for (int bi = 0; bi < N; bi += B)
                for (int bj = 0; bj < N; bj += B) {
                    bool any = false, valid = false;
                    for (int i = bi; i < std::min(N, bi + B); ++i)
                        for (int j = bj; j < std::min(N, bj + B); ++j) {
                            const double v = at(i, j);
                            valid = valid || (v >= 0.0 && v < kPairInvalid);
                            any = any || (v >= 0.0 && v <= thr + float_bound);
                        }
                    blocks += valid, needed += valid && any;
                }
            state.counters["blocks" + std::to_string(B)] = static_cast<double>(needed) / static_cast<double>(blocks);
        }
        state.counters["frames"] = N;
        state.counters["threshold"] = thr;
        state.counters["float_bound"] = float_bound;
        state.counters["double_bound"] = window_distance_error_bound(f, 512 + 2 * h + 10).distance;
    }
}

}  // namespace

BENCHMARK(BM_ControllerCircleActionsDefault)->Arg(64)->Unit(benchmark::kMicrosecond)->Iterations(240 * 150);
BENCHMARK(BM_ControllerCircleActionsCmu16)->Arg(64)->Unit(benchmark::kMicrosecond)->Iterations(240 * 150);
BENCHMARK(BM_BuildCmu16)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_FloatProposalStudy)->Arg(3000)->Unit(benchmark::kSecond)->Iterations(1);  // a study: minutes
BENCHMARK(BM_ReferenceSpeedup)->Arg(1000)->Arg(2000)->Arg(3000)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_TiledSearch)->Arg(1000)->Arg(3000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PathQuery)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ControllerCircleCmu16)->Arg(64)->Arg(256)->Unit(benchmark::kMicrosecond)->Iterations(36000);
BENCHMARK(BM_BuildSynthetic)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_MAIN();
