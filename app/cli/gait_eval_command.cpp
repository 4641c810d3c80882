// `marionette gait-eval`: runs the gait (or, with --graph, a motion graph) headless
// over a stick program on a terrain and prints the metrics of docs/gait.md;
// --check makes a broken limit exit 1 (with --graph: a metric that is not finite).
// --sweep N --seed S runs N generated cases of the envelope instead (docs/gait.md,
// "The envelope"; app/eval/gait_sweep.hpp).
#include <fmt/format.h>

#include <memory>

#include "app/cli/cli.hpp"
#include "app/io/log.hpp"
#include "app/config/config.hpp"
#include "app/eval/gait_eval.hpp"
#include "app/eval/gait_sweep.hpp"
#include "app/graph/graph_files.hpp"
#include "app/io/json.hpp"
#include "app/config/program_source.hpp"
#include "app/config/terrain_file.hpp"

namespace marionette {

namespace {
struct GaitEvalOptions {
    std::string terrain;
    std::string program;
    std::string config_file;
    std::string feet_csv;
    std::string graph_file;
    bool json = false;
    bool check = false;
    int sweep = -1;           // given: run this many generated cases
    std::uint64_t seed = 1;
    std::string out_dir;      // --sweep: failing cases' .prog and .toml go here
};

std::string sweep_json(const SweepSummary& s) {
    std::string worst, by_ground, failures;
    for (int m = 0; m < kSweepMetricCount; ++m)
        worst += fmt::format("{}{}:{{\"value\":{},\"case\":{},\"limit\":{},\"failing_cases\":{}}}", m ? "," : "",
                             json::quote(kSweepMetrics[m].name), json::number(s.worst[m].value),
                             s.worst[m].case_id.empty() ? std::string("null") : json::quote(s.worst[m].case_id),
                             json::number(kSweepMetrics[m].limit), s.failed_by_metric[m]);
    for (int g = 0; g < kSweepGroundCount; ++g)
        by_ground += fmt::format("{}{}:{{\"cases\":{},\"failed\":{}}}", g ? "," : "",
                                 json::quote(sweep_ground_name(static_cast<SweepGround>(g))), s.cases_by_ground[g],
                                 s.failed_by_ground[g]);
    for (const SweepFailure& f : s.failures) {
        failures += fmt::format("{}{{\"case\":{},\"ground\":{},\"description\":{},\"problem\":{}", failures.empty() ? "" : ",",
                                json::quote(f.case_id), json::quote(sweep_ground_name(f.ground)), json::quote(f.description),
                                json::quote(f.problem));
        for (const SweepMetric& metric : kSweepMetrics)
            failures += fmt::format(",{}:{}", json::quote(metric.name), json::number(f.metrics.*metric.value));
        failures += fmt::format(",\"fastest_joint\":{},\"fastest_joint_tick\":{}}}", json::quote(f.metrics.fastest_joint),
                                f.metrics.fastest_joint_tick);
    }
    return fmt::format("{{\"seed\":{},\"cases\":{},\"passed\":{},\"failed\":{},\"ticks\":{},\"worst\":{{{}}},"
                       "\"by_ground\":{{{}}},\"failures\":[{}]}}\n",
                       s.seed, s.cases, s.passed, s.cases - s.passed, s.ticks, worst, by_ground, failures);
}

void print_sweep_text(const SweepSummary& s) {
    fmt::print("gait-eval --sweep {} --seed {}: {} passed, {} failed ({} ticks simulated)\n", s.cases, s.seed, s.passed,
               s.cases - s.passed, s.ticks);
    fmt::print("  {:<24}{:>14}  {:<10}{:>10}  {}\n", "metric", "worst", "limit", "failing", "worst case");
    for (int m = 0; m < kSweepMetricCount; ++m)
        fmt::print("  {:<24}{:>14.4f}  < {:<8}{:>10}  {}\n", kSweepMetrics[m].name, s.worst[m].value, kSweepMetrics[m].limit,
                   s.failed_by_metric[m], s.worst[m].case_id.empty() ? "-" : s.worst[m].case_id);
    fmt::print("  by ground:");
    for (int g = 0; g < kSweepGroundCount; ++g)
        fmt::print(" {} {}/{}", sweep_ground_name(static_cast<SweepGround>(g)), s.cases_by_ground[g] - s.failed_by_ground[g],
                   s.cases_by_ground[g]);
    fmt::print(" passed\n");
    for (const SweepFailure& f : s.failures)
        fmt::print("  FAILED {}: {}\n      {}\n      fastest joint: {} at tick {}\n", f.case_id, f.problem, f.description,
                   f.metrics.fastest_joint, f.metrics.fastest_joint_tick);
}

int gait_sweep_command(const GaitEvalOptions& o) {
    if (o.sweep < 1 || o.sweep > 1000000) throw ImportError("--sweep", 0, fmt::format("{}: expected a number of cases from 1 to 1000000", o.sweep));
    if (!o.graph_file.empty() || !o.feet_csv.empty() || !o.program.empty() || !o.terrain.empty())
        throw ImportError("--sweep", 0, "generates its own programs and terrains: it takes no --program, --terrain, --graph or --feet-csv");
    const AppConfig app = load_config(o.config_file);
    const SweepSummary s = run_gait_sweep(app.sim, o.seed, o.sweep, o.out_dir);
    if (o.json) fmt::print("{}", sweep_json(s));
    else print_sweep_text(s);
    if (o.check && s.passed != s.cases) {
        log_message(LogLevel::error, fmt::format("gait-eval --sweep {} --seed {}: {} of {} cases broke a limit", o.sweep,
                                                 o.seed, s.cases - s.passed, s.cases));
        return 1;
    }
    return 0;
}

// A turn time in the JSON: seconds, or null when there was no turn or one never got there.
std::string turn_time_json(double seconds, bool any) { return any && seconds >= 0.0 ? json::number(seconds) : "null"; }

std::string turns_json(const GaitMetrics& m) {
    std::string out = "[";
    for (const TurnTime& t : m.turns)
        out += fmt::format("{}{{\"tick\":{},\"angle_deg\":{},\"time_s\":{},\"after_stick_s\":{}}}", out.size() > 1 ? "," : "", t.tick,
                           json::number(t.angle_deg), turn_time_json(t.time_s, true), turn_time_json(t.after_stick_s, true));
    return out + "]";
}

int gait_eval_command(const GaitEvalOptions& o) {
    if (o.sweep != -1) return gait_sweep_command(o);
    if (!o.out_dir.empty()) throw ImportError("--out", 0, "only with --sweep (where failing cases are written)");
    if (o.program.empty()) throw ImportError("--program", 0, "required (a stick program file or builtin:NAME), unless --sweep is given");
    const AppConfig app = load_config(o.config_file);
    SimConfig config = app.sim;
    if (!o.terrain.empty()) {
        config.terrain = load_terrain(o.terrain);
        config.terrain_name = o.terrain;
    }
    const StickProgram program = load_program(o.program);
    // No --graph with [motion] source = graph/graph_feet: the embedded default graph.
    auto graph = load_graph_argument(o.graph_file, config, app.graph_build);
    const bool with_graph = graph != nullptr;
    const std::string graph_name = o.graph_file.empty() ? std::string("default") : o.graph_file;
    const GaitMetrics m = evaluate_gait(config, program, o.feet_csv, std::move(graph));
    // The limits are the procedural gait's (docs/gait.md). A graph plays captured
    // motion without contact pinning yet, so with --graph the metrics are reported
    // and only a metric that is not a finite number fails --check.
    const Outcome checked = with_graph ? check_gait_metrics_finite(m) : check_gait_limits(m);
    if (o.json) {
        fmt::print("{{\"terrain\":{},\"program\":{},\"motion_source\":{},\"graph\":{},\"ticks\":{},\"foot_skate_mm\":{},"
                   "\"penetration_mm\":{},\"speed_error_pct\":{},\"speed_expectation\":{},\"speed_windows\":{},"
                   "\"max_joint_speed_deg_s\":{},\"fastest_joint\":{},\"fastest_joint_tick\":{},\"obstacle_penetration_mm\":{},\"turn_time_s\":{},\"turns\":{},"
                   "\"steps\":{},\"flight_phases\":{},\"final_hash\":\"{:016x}\",\"limits_ok\":{},"
                   "\"distance_m\":{},\"distance_ratio_to_gait\":{},\"start_latency_s\":{},\"heading_error_deg\":{},\"heading_samples\":{},\"pop_ratio\":{}}}\n",
                   json::quote(config.terrain_name), json::quote(o.program), json::quote(m.motion_source),
                   with_graph ? json::quote(graph_name) : std::string("null"), m.ticks, json::number(m.foot_skate_mm),
                   json::number(m.penetration_mm), json::number(m.speed_error_pct), json::quote(m.speed_expectation),
                   m.speed_windows, json::number(m.max_joint_speed_deg_s), json::quote(m.fastest_joint), m.fastest_joint_tick,
                   json::number(m.obstacle_penetration_mm),
                   turn_time_json(m.turn_time_s, !m.turns.empty()), turns_json(m), m.steps, m.flight_phases, m.final_hash,
                   with_graph ? "null" : checked.ok() ? "true" : "false", json::number(m.distance_m),
                   json::number(m.distance_ratio_to_gait), json::number(m.start_latency_s), json::number(m.heading_error_deg), m.heading_samples,
                   json::number(m.pop_ratio));
    } else {
        fmt::print("gait-eval: {} on {} ({} ticks, motion from {})\n", o.program, config.terrain_name, m.ticks,
                   with_graph ? m.motion_source + " from graph " + graph_name : std::string("the gait"));
        if (with_graph) fmt::print("  (the gait's limits are not applied to a graph; speed expected from {})\n", m.speed_expectation);
        fmt::print("  foot_skate_mm          {:10.4f}  (limit < {}; worst at tick {})\n", m.foot_skate_mm, kMaxFootSkateMm, m.skate_tick);
        fmt::print("  penetration_mm         {:10.4f}  (limit < {}; deepest: {} at tick {})\n", m.penetration_mm,
                   kMaxPenetrationMm, m.deepest_point.empty() ? "none" : m.deepest_point, m.deepest_tick);
        fmt::print("  speed_error_pct        {:10.4f}  (limit < {}; {} holds measured)\n", m.speed_error_pct,
                   kMaxSpeedErrorPct, m.speed_windows);
        fmt::print("  max_joint_speed_deg_s  {:10.1f}  (limit < {}; {} at tick {})\n", m.max_joint_speed_deg_s, kMaxJointSpeedDegS,
                   m.fastest_joint, m.fastest_joint_tick);
        fmt::print("  distance_m             {:10.3f}  (ratio to the gait {:.3f})\n", m.distance_m, m.distance_ratio_to_gait);
        fmt::print("  start_latency_s        {:10.3f}  (stick from rest to root speed >= 0.5 m/s, worst; -1: never)\n", m.start_latency_s);
        fmt::print("  heading_error_deg      {:10.3f}  (mean over the second half of each moving hold, {} ticks; -1: no moving hold)\n",
                   m.heading_error_deg, m.heading_samples);
        fmt::print("  pop_ratio              {:10.3f}  (largest per-tick joint move over its 95th percentile)\n", m.pop_ratio);
        fmt::print("  obstacle_penetration_mm {:9.4f}  (limit < {}; deepest: {} at tick {})\n", m.obstacle_penetration_mm,
                   kMaxObstaclePenetrationMm, m.obstacle_point.empty() ? "none" : m.obstacle_point, m.obstacle_tick);
        for (const TurnTime& t : m.turns)
            fmt::print("  turn at tick {:5} of {:5.1f} deg: heading within {} deg after {} s ({} s after the stick settled)\n", t.tick,
                       t.angle_deg, kTurnToleranceDeg, t.time_s < 0.0 ? std::string("never") : fmt::format("{:.3f}", t.time_s),
                       t.after_stick_s < 0.0 ? std::string("-") : fmt::format("{:.3f}", t.after_stick_s));
        fmt::print("  steps {}  flight_phases {}  final hash {:016x}\n", m.steps, m.flight_phases, m.final_hash);
        if (!checked.ok()) fmt::print("  {}: {}\n", with_graph ? "NOT FINITE" : "LIMITS BROKEN", checked.problem());
    }
    if (o.check && !checked.ok()) {
        log_message(LogLevel::info, fmt::format("gait-eval: {} on {}: {}", o.program, config.terrain_name, checked.problem()));
        return 1;
    }
    return 0;
}
}  // namespace

void register_gait_eval_command(CLI::App& app, int& exit_code) {
    auto o = std::make_shared<GaitEvalOptions>();
    CLI::App* cmd = app.add_subcommand("gait-eval", "Run the gait headless over a stick program on a terrain and print its metrics");
    cmd->add_option("--terrain", o->terrain, "terrain file, or a built-in name (flat, stairs, slope, rubble, building_stairs, hillside, wall); default: the config's");
    cmd->add_option("--program", o->program, "stick program file, or builtin:NAME (required without --sweep)");
    cmd->add_option("--config", o->config_file, "TOML file overriding the defaults")->check(CLI::ExistingFile);
    cmd->add_option("--graph", o->graph_file, "drive the puppet from this motion graph (.mgraph, or default: the embedded one)");
    cmd->add_option("--feet-csv", o->feet_csv, "write a per-tick CSV of both feet (clearance of each sole point) here");
    cmd->add_flag("--json", o->json, "print one JSON object");
    cmd->add_flag("--check", o->check, "exit 1 when a metric breaks its limit (with --graph: when a metric is not finite)");
    cmd->add_option("--sweep", o->sweep, "run N cases generated over the envelope (docs/gait.md) instead of one program");
    cmd->add_option("--seed", o->seed, "--sweep: the generator's seed (default 1); the same seed gives the same cases");
    cmd->add_option("--out", o->out_dir, "--sweep: write each failing case's ID.prog and ID.toml into this folder");
    on_parsed(cmd, exit_code, [o] { return gait_eval_command(*o); });
}

}  // namespace marionette
