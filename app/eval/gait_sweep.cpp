#include "app/eval/gait_sweep.hpp"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>

#include "app/config/terrain_file.hpp"
#include "app/eval/gait_sweep_detail.hpp"
#include "app/io/files.hpp"

namespace marionette {

namespace {

// Case i of seed S draws from its own stream: splitmix64 of S, then of i, so a
// case is the same whatever N is and neighbouring seeds share no cases.
std::uint64_t case_seed(std::uint64_t seed, int index) {
    SweepRandom outer(seed);
    const std::uint64_t base = outer.next();
    SweepRandom inner(base ^ (static_cast<std::uint64_t>(index) * 0xD1B54A32D192ED03ull));
    return inner.next();
}

}  // namespace

SweepCase generate_sweep_case(std::uint64_t seed, int index, const SimConfig& config) {
    SweepCase c;
    c.seed = seed;
    c.index = index;
    c.id = fmt::format("{}-{:04}", seed, index);
    SweepRandom r(case_seed(seed, index));
    double first_dir = 90.0;
    std::string ground = sweep_detail::make_ground(r, c.ground, c.terrain, first_dir);
    if (c.ground.kind != SweepGround::flat && c.ground.kind != SweepGround::heightfield)
        ground += fmt::format(", approached {:.0f}° off its axis", c.ground.approach_deg);
    std::string program_summary;
    const std::string moves = sweep_detail::make_program(r, first_dir, config.stick_deadzone, program_summary);
    c.description = ground + "; program " + program_summary;
    c.speed_checked = c.ground.kind != SweepGround::wall;
    c.program_text = fmt::format("# gait-eval --sweep case {} (seed {}, case {})\n# ground: {}\n# program: {}\n"
                                 "# Replay: marionette gait-eval --terrain {}.toml --program {}.prog\n{}",
                                 c.id, seed, index, ground, program_summary, c.id, c.id, moves);
    c.program = parse_stick_program(c.program_text, c.id + ".prog");
    c.program.name = c.id;
    return c;
}

SweepCaseResult evaluate_sweep_case(const SweepCase& sweep_case, const SimConfig& base) {
    SimConfig config = base;
    config.terrain = sweep_case.terrain;
    config.terrain_name = sweep_case.id + ".toml";
    SweepCaseResult result;
    result.metrics = evaluate_gait(config, sweep_case.program);
    GaitMetrics judged = result.metrics;
    if (!sweep_case.speed_checked) judged.speed_error_pct = 0.0;
    const Outcome ok = check_gait_limits(judged);
    if (!ok.ok()) result.problem = ok.problem();
    return result;
}

std::string sweep_program_file_text(const SweepCase& c) {
    return c.program_text;
}

std::string sweep_terrain_file_text(const SweepCase& c) {
    return fmt::format("# gait-eval --sweep case {} (seed {}, case {}): {}\n"
                       "# Replay: marionette gait-eval --terrain {}.toml --program {}.prog{}\n{}",
                       c.id, c.seed, c.index, c.description, c.id, c.id,
                       c.speed_checked ? "" : "\n# (a wall denies the stick its speed: speed_error_pct is not a limit here)",
                       serialize_terrain(c.terrain, ""));
}

SweepSummary run_gait_sweep(const SimConfig& base, std::uint64_t seed, int count, const std::string& out_dir) {
    SweepSummary s;
    s.seed = seed;
    if (!out_dir.empty()) std::filesystem::create_directories(out_dir);
    for (int i = 0; i < count; ++i) {
        const SweepCase c = generate_sweep_case(seed, i, base);
        const SweepCaseResult result = evaluate_sweep_case(c, base);
        const int ground = static_cast<int>(c.ground.kind);
        ++s.cases;
        ++s.cases_by_ground[ground];
        s.ticks += result.metrics.ticks;
        for (int m = 0; m < kSweepMetricCount; ++m) {
            const SweepMetric& metric = kSweepMetrics[m];
            if (metric.value == &GaitMetrics::speed_error_pct && !c.speed_checked) continue;
            const double value = result.metrics.*metric.value;
            // A NaN is the worst value there is: the first one stays.
            const double worst = s.worst[m].value;
            if (s.worst[m].case_id.empty() || (!std::isnan(worst) && !(value <= worst))) {
                s.worst[m].value = value;
                s.worst[m].case_id = c.id;
            }
            if (!(value < metric.limit)) ++s.failed_by_metric[m];
        }
        if (result.problem.empty()) {
            ++s.passed;
            continue;
        }
        ++s.failed_by_ground[ground];
        s.failures.push_back({c.id, c.ground.kind, c.description, result.problem, result.metrics});
        if (!out_dir.empty()) {
            const std::filesystem::path dir(out_dir);
            write_text_file((dir / (c.id + ".prog")).string(), sweep_program_file_text(c));
            write_text_file((dir / (c.id + ".toml")).string(), sweep_terrain_file_text(c));
        }
    }
    return s;
}

}  // namespace marionette
