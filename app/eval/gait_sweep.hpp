#pragma once
// `gait-eval --sweep N --seed S`: N random cases drawn from the gait's envelope
// (docs/gait.md, "The envelope") — a stick program in the stick-program text
// format × a terrain (stairs, ramps, hillsides, heightfields, curbs, walls) —
// each run through evaluate_gait, with the worst value of every metric and the
// failing cases reported. Generation uses only integer random numbers, IEEE
// arithmetic and det_math, so a seed gives the same cases on every machine.
#include <cstdint>
#include <string>
#include <vector>

#include "app/eval/gait_eval.hpp"
#include "runtime/formats/stick_program.hpp"
#include "runtime/ground/terrain.hpp"
#include "runtime/math/splitmix64.hpp"
#include "runtime/sim/sim_config.hpp"

namespace marionette {

// splitmix64 (Steele, Lea, Flood 2014), written out here: every draw is integer
// arithmetic, and floats come from the top 53 bits, so the sequence does not
// depend on the standard library (std::uniform_*_distribution does).
class SweepRandom {
public:
    explicit SweepRandom(std::uint64_t seed) : state_(seed) {}
    std::uint64_t next() { return splitmix64_next(state_); }
    double uniform() { return splitmix64_unit(state_); }  // [0, 1)
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
    // Inclusive range; the modulo bias is below 2^-32 for the small ranges used here.
    int integer(int lo, int hi) {
        return lo + static_cast<int>(next() % static_cast<std::uint64_t>(hi - lo + 1));
    }
    bool chance(double p) { return uniform() < p; }
    bool coin() { return (next() & 1u) != 0; }  // one bit: a fair coin

private:
    std::uint64_t state_;
};

// The envelope's limits (docs/gait.md, "The envelope"): what the generator draws
// within, and what the tests check every generated case against.
namespace sweep_envelope {
inline constexpr double kMaxStairRiseM = 0.22;
inline constexpr double kMinStairTreadM = 0.25;
inline constexpr double kMaxTreadM = 0.60;
inline constexpr double kMaxOffAxisDeg = 60.0;    // stairs, curbs and walls are approached within this of their axis
inline constexpr double kMaxSlopeDeg = 30.0;      // ramps, hillsides and heightfield grades
inline constexpr double kMaxReliefM = 0.30;       // heightfields: heights within ±this ...
inline constexpr double kMinReliefSpanM = 2.0;    // ... varying over no less than this
inline constexpr double kMaxStepHeightM = 0.35;   // curbs and ledges; a box taller than this is an obstacle
inline constexpr double kMinWallHeightM = 0.40;   // walls are boxes this tall or taller (above kMaxStepHeightM)
inline constexpr double kMaxWallHeightM = 2.50;
inline constexpr double kWallClearanceM = 0.40;   // no wall within this of the puppet's start
inline constexpr double kGroundHalfSpanM = 45.0;  // stairs, ramps, curbs and hillsides reach this far: no drop at a side
inline constexpr double kMinCaseS = 6.0;          // a case's simulated time
inline constexpr double kMaxCaseS = 12.0;
}  // namespace sweep_envelope

enum class SweepGround : std::uint8_t { flat, stairs, ramp, hillside, heightfield, curb, wall };
inline constexpr int kSweepGroundCount = 7;
const char* sweep_ground_name(SweepGround ground);

// What a case's ground was drawn as (the tests check these against the envelope
// and against the terrain built from them). Angles are stick angles in degrees:
// 0 = stick right (+X), 90 = stick up (−Z), as `circle from=` counts them.
struct SweepGroundParams {
    SweepGround kind = SweepGround::flat;
    double axis_deg = 90.0;      // the feature's axis (stairs and ramps rise along it, walls stand across it)
    double approach_deg = 0.0;   // first stick direction minus axis_deg, in (−180, 180]
    // stairs
    double rise_m = 0.0, tread_m = 0.0, landing_m = 0.0;
    int risers_per_flight = 0, flights = 0;
    bool start_on_top = false;   // stairs and ramps: start on the top, going down first
    // ramps and hillsides
    double slope_deg = 0.0;
    // heightfield
    double relief_m = 0.0, relief_span_m = 0.0;
    // curbs
    double largest_ledge_m = 0.0;
    int ledges = 0;
    // walls
    int walls = 0;
};

struct SweepCase {
    std::uint64_t seed = 0;
    int index = 0;
    std::string id;             // "S-IIII": the sweep's seed and the case's index
    SweepGroundParams ground;
    std::string description;    // one line: the ground and the program's shape
    std::string program_text;   // the stick program, as saved with --out
    StickProgram program;       // program_text parsed
    Terrain terrain;
    // A wall in the way denies the stick its speed, so speed_error_pct is not a
    // limit for a case with walls (docs/gait.md, "The envelope").
    bool speed_checked = true;
};

// Case `index` of the sweep seeded `seed`; the same case whatever N is. The
// config gives the stick's dead zone (values near it are drawn on purpose).
SweepCase generate_sweep_case(std::uint64_t seed, int index, const SimConfig& config);

// The metrics the sweep reports the worst of. A new GaitMetrics metric with a
// limit is one more line here (and one in check_gait_limits).
struct SweepMetric {
    const char* name;
    double limit;
    double GaitMetrics::*value;
};
inline constexpr SweepMetric kSweepMetrics[] = {
    {"foot_skate_mm", kMaxFootSkateMm, &GaitMetrics::foot_skate_mm},
    {"penetration_mm", kMaxPenetrationMm, &GaitMetrics::penetration_mm},
    {"speed_error_pct", kMaxSpeedErrorPct, &GaitMetrics::speed_error_pct},
    {"max_joint_speed_deg_s", kMaxJointSpeedDegS, &GaitMetrics::max_joint_speed_deg_s},
    {"obstacle_penetration_mm", kMaxObstaclePenetrationMm, &GaitMetrics::obstacle_penetration_mm},
};
inline constexpr int kSweepMetricCount = static_cast<int>(sizeof(kSweepMetrics) / sizeof(kSweepMetrics[0]));

// One case's metrics as the sweep judges them: speed_error_pct is zeroed where
// it is not a limit (speed_checked false); `problem` is empty when all hold.
struct SweepCaseResult {
    GaitMetrics metrics;
    std::string problem;
};
SweepCaseResult evaluate_sweep_case(const SweepCase& sweep_case, const SimConfig& base);

struct SweepWorst {
    double value = 0.0;
    std::string case_id;  // empty: no case measured it
};

struct SweepFailure {
    std::string case_id;
    SweepGround ground = SweepGround::flat;
    std::string description;
    std::string problem;
    GaitMetrics metrics;
};

struct SweepSummary {
    std::uint64_t seed = 0;
    int cases = 0;
    int passed = 0;
    std::uint64_t ticks = 0;
    SweepWorst worst[kSweepMetricCount];
    int cases_by_ground[kSweepGroundCount] = {};
    int failed_by_ground[kSweepGroundCount] = {};
    int failed_by_metric[kSweepMetricCount] = {};
    std::vector<SweepFailure> failures;  // in case order
};

// Runs cases 0..count−1 of `seed` over `base` (its terrain replaced by each
// case's). `out_dir` not empty: each failing case's ID.prog and ID.toml are
// written there (the folder is created), replayable with the plain gait-eval.
SweepSummary run_gait_sweep(const SimConfig& base, std::uint64_t seed, int count, const std::string& out_dir);

// The files --out writes for a case (header comments say how to replay them).
std::string sweep_program_file_text(const SweepCase& sweep_case);
std::string sweep_terrain_file_text(const SweepCase& sweep_case);

}  // namespace marionette
