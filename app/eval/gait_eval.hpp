#pragma once
// Measures a gait run (docs/gait.md, "Metrics"): the simulation runs headless over
// a stick program and every metric is computed from the simulated joint
// positions against the terrain, not from what the planner intended.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "runtime/errors/outcome.hpp"
#include "runtime/graph/motion_graph.hpp"
#include "runtime/sim/sim_config.hpp"
#include "runtime/formats/stick_program.hpp"

namespace marionette {

struct PuppetState;

// One change of the stick's direction followed by a hold (docs/gait.md,
// "Metrics"): how long the heading took to come within kTurnToleranceDeg of it.
struct TurnTime {
    std::uint64_t tick = 0;      // the stick's change began (the first tick after the previous hold)
    double angle_deg = 0.0;      // the stick's direction − the heading then
    double time_s = -1.0;        // from the change's start; < 0: not within the tolerance before the hold ended
    double after_stick_s = -1.0; // from when the stick reached its direction (the hold's start)
};

struct GaitMetrics {
    // What drove the puppet: "gait" (the procedural gait) or "graph" (a motion graph).
    std::string motion_source = "gait";
    // Where speed_error_pct's expected speed comes from (docs/gait.md).
    std::string speed_expectation = "gait response curve";
    double foot_skate_mm = 0.0;          // largest horizontal drift of a foot joint during one stance
    double penetration_mm = 0.0;         // deepest sole or toe point below the surface
    double speed_error_pct = 0.0;        // worst steady-state speed error over the program's holds
    double max_joint_speed_deg_s = 0.0;  // largest angular speed of any joint's local rotation
    double obstacle_penetration_mm = 0.0;  // deepest joint or sole point inside an obstacle box
    std::vector<TurnTime> turns;         // every stick direction change of at least kMinTurnDeg
    double turn_time_s = 0.0;            // the slowest of them (time_s; < 0 when one never got there)
    // Issue 14's measures, for every source (docs/motion-matching.md):
    double distance_m = 0.0;             // root path length over the program (sampled every quarter second)
    double distance_ratio_to_gait = 1.0; // distance_m over the gait's for the same program and terrain
    double start_latency_s = 0.0;        // worst: stick pushed from rest → root speed ≥ 0.5 m/s (−1: never)
    double heading_error_deg = 0.0;      // mean |stick direction − heading| over the second half of each moving hold (−1: no such tick)
    std::int64_t heading_samples = 0;    // ticks that mean is over (0: the program has no moving hold, e.g. circle)
    double pop_ratio = 0.0;              // largest per-tick joint move over its 95th percentile
    int steps = 0;                       // touchdowns seen in the sole heights
    int flight_phases = 0;               // intervals with both feet off the ground
    int speed_windows = 0;               // holds long enough to measure the speed over
    std::uint64_t ticks = 0;
    std::uint64_t final_hash = 0;
    // Where the worst values happened, for diagnosis.
    std::string fastest_joint;
    std::uint64_t fastest_joint_tick = 0;
    std::uint64_t deepest_tick = 0;
    std::string deepest_point;           // e.g. "foot_l toe tip (swing)"
    std::uint64_t skate_tick = 0;
    std::string obstacle_point;          // e.g. "shin_l"
    std::uint64_t obstacle_tick = 0;
};

// The limits (docs/gait.md).
inline constexpr double kMaxFootSkateMm = 0.5;
inline constexpr double kMaxPenetrationMm = 1.0;
inline constexpr double kMaxSpeedErrorPct = 2.0;
inline constexpr double kMaxJointSpeedDegS = 1500.0;
inline constexpr double kMaxObstaclePenetrationMm = 1.0;
// Turn times: stick changes of at least kMinTurnDeg from the heading, done when
// the heading is within kTurnToleranceDeg of the stick.
inline constexpr double kMinTurnDeg = 20.0;
inline constexpr double kTurnToleranceDeg = 10.0;

// Ok when every limit holds, else which failed and by how much.
Outcome check_gait_limits(const GaitMetrics& metrics);

// Ok when every metric is a finite number, else the first that is not (the
// only check `gait-eval --check --graph` applies: docs/gait.md).
Outcome check_gait_metrics_finite(const GaitMetrics& metrics);

// Whether foot 0 (left) or 1 (right) is planted in `state`, as the metrics read
// stance: the gait's plan (not swinging) when the gait drives the puppet, the
// graph controller's per-frame foot contacts when a motion graph does. The one
// place that decides where stance comes from.
bool foot_in_stance(const PuppetState& state, int foot);

// The heading error of one tick: |the stick's direction (atan2(x, −y), the
// gait's convention) − heading|, wrapped to [0, 180] degrees.
double stick_heading_error_deg(double stick_x, double stick_y, double heading);

// heading_error_deg over a run: the mean of stick_heading_error_deg over the
// ticks in the second half of each moving hold [first_tick, end_tick).
class HeadingErrorMeter {
public:
    struct Hold {
        std::uint64_t first_tick, end_tick;  // end exclusive
        double stick_x, stick_y;
    };
    explicit HeadingErrorMeter(std::vector<Hold> holds) : holds_(std::move(holds)) {}
    void add(std::uint64_t tick, double heading);
    // The mean in degrees, −1 when no tick was in a hold's second half.
    double mean_deg() const { return samples_ > 0 ? sum_ / static_cast<double>(samples_) : -1.0; }
    std::int64_t samples() const { return samples_; }

private:
    std::vector<Hold> holds_;
    double sum_ = 0.0;
    std::int64_t samples_ = 0;
};

// `feet_csv`: when not empty, a per-tick CSV of both feet (swing flag, progress,
// each sole point's height above the ground) is written there, for diagnosis.
// `graph`: when given, the puppet is driven by it (attach_motion_graph, as
// `--graph` on record/replay/run) and the metrics read the graph's feet.
GaitMetrics evaluate_gait(const SimConfig& config, const StickProgram& program, const std::string& feet_csv = {},
                          std::shared_ptr<const MotionGraph> graph = nullptr);

}  // namespace marionette
