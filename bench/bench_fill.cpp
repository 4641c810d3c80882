// Filling hidden joints (issue 15, docs/fill.md). Not a test: run by hand.
//   build/release/bench/marionette_bench_fill
// The target: a 4 s gap in a 2-minute clip against a 10,000-frame database in
// under 1 s. The clip is the CMU subject-16 clips (MARIONETTE_MOCAP_DIR, default
// ../shared/data/mocap) one after another at 120 Hz until 2 minutes; the database
// is the same clips at 30 Hz, concatenated (~760 frames a clip), each copy
// turned by a different heading, until 10,000 frames.
#include <benchmark/benchmark.h>

#include <cstdlib>

#include "graph_builder/clip_fill.hpp"
#include "runtime/formats/asf_amc.hpp"

using namespace marionette;
using namespace marionette::offline;

namespace {

std::string mocap_dir() {
    const char* env = std::getenv("MARIONETTE_MOCAP_DIR");
    return env && *env ? env : MARIONETTE_DEFAULT_MOCAP_DIR;
}

std::vector<Clip> cmu16() {
    std::vector<Clip> clips;
    for (const char* c : {"16_11", "16_15", "16_17", "16_19", "16_33", "16_35", "16_41", "16_43", "16_57"})
        clips.push_back(load_asf_amc_files(mocap_dir() + "/cmu_amc_16/16.asf", mocap_dir() + "/cmu_amc_16/" + c + ".amc"));
    return clips;
}

Clip two_minutes(const std::vector<Clip>& clips) {
    Clip out = clips.front();
    out.name = "two_minutes";
    for (size_t k = 1; out.frame_count < 120 * 120; ++k) {
        const Clip& c = clips[k % clips.size()];
        out.rotations.insert(out.rotations.end(), c.rotations.begin(), c.rotations.end());
        out.translations.insert(out.translations.end(), c.translations.begin(), c.translations.end());
        out.frame_count += c.frame_count;
    }
    return out;
}

const FillDatabase& database() {
    static const FillDatabase db = [] {
        std::vector<Clip> clips = cmu16(), copies;
        std::int64_t frames = 0;
        for (Clip& c : clips) c = resample_clip(c, 30.0);
        for (int k = 0; frames < 10000; ++k) {
            // Each database clip: the nine clips one after another (~760 frames),
            // so every placement of a 5 s query has room.
            Clip c = two_minutes(clips);
            c.frame_count = 0;
            c.rotations.clear();
            c.translations.clear();
            for (size_t i = 0; i < clips.size(); ++i) {
                const Clip& part = clips[(i + static_cast<size_t>(k)) % clips.size()];
                c.rotations.insert(c.rotations.end(), part.rotations.begin(), part.rotations.end());
                c.translations.insert(c.translations.end(), part.translations.begin(), part.translations.end());
                c.frame_count += part.frame_count;
            }
            c.frame_rate = 30.0;
            c.name += "_" + std::to_string(k);
            const quat turn = quat_axis_angle(vec3(0, 1, 0), 0.37 * k);
            for (int f = 0; f < c.frame_count; ++f) {
                const size_t i = static_cast<size_t>(f) * static_cast<size_t>(c.joint_count());
                c.rotations[i] = quat_mul(turn, c.rotations[i]);
                c.translations[i] = quat_rotate(turn, c.translations[i]);
            }
            frames += c.frame_count;
            copies.push_back(std::move(c));
        }
        return prepare_fill_database(std::move(copies));
    }();
    return db;
}

void BM_PrepareDatabase(benchmark::State& state) {
    std::vector<Clip> clips = cmu16();
    for (auto _ : state) {
        const FillDatabase db = prepare_fill_database(clips);
        benchmark::DoNotOptimize(db.positions.data());
    }
    state.counters["frames"] = static_cast<double>(prepare_fill_database(clips).frame_count());
}

void BM_FillGap4s(benchmark::State& state) {
    const Clip input = two_minutes(cmu16());
    const FillDatabase& db = database();
    FillGap g;
    g.hidden = resolve_hidden_joints(input.skeleton, state.range(0) ? "arms" : "legs", "--hide");
    g.first = 60 * 120;
    g.last = g.first + 4 * 120 - 1;
    for (auto _ : state) {
        Clip c = input;
        const FillMatch m = fill_gap(c, g, &db, FillOptions{});
        benchmark::DoNotOptimize(m.distance);
    }
    state.counters["database_frames"] = static_cast<double>(db.frame_count());
    state.counters["clip_frames"] = input.frame_count;
}

}  // namespace

BENCHMARK(BM_PrepareDatabase)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FillGap4s)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_MAIN();
