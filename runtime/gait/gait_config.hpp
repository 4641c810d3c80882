#pragma once
// What the gait and the puppet's build read from the configuration: the
// [puppet], [locomotion] and [gait] tables (docs/config.md). Plain data; the
// TOML schema and validation live in app/config/config.cpp.
#include "runtime/gait/gait_prototype.hpp"

namespace marionette {

struct GaitConfig {
    // [puppet] proportions in metres
    float pelvis_height = 0.95f;           // hip joint height above the ground when standing
    float hip_width = 0.18f;
    float thigh_length = 0.44f;
    float shin_length = 0.43f;
    float ankle_height = 0.08f;
    float foot_length = 0.14f;
    float toe_length = 0.06f;
    float spine_length = 0.50f;            // pelvis to neck, split over three spine joints
    float neck_length = 0.10f;
    float head_length = 0.22f;
    float shoulder_width = 0.36f;
    float upper_arm_length = 0.29f;
    float forearm_length = 0.26f;
    float hand_length = 0.18f;

    // [locomotion]
    float max_speed = 3.0f;                // m/s at full stick deflection
    float walk_cycle_speed = 1.4f;         // speed the generated walk clip plays at 1×
    float stride_length = 1.4f;            // metres per full walk cycle at walk_cycle_speed
    float acceleration = 6.0f;             // m/s² toward the commanded velocity
    float turn_rate_deg_s = 360.0f;        // heading follows the movement direction
    float stick_deadzone = 0.12f;          // radial, fraction of full deflection
    float response_curve = 0.5f;           // 0 linear … 1 quadratic: f(d) = (1−c)·d + c·d²

    // [gait] the spline-IK gait (docs/gait.md)
    float gait_pelvis_height = 0.84f;      // hip height above the mean foot ground while stepping
    float step_length_multiplier = 0.45f;  // step length = multiplier · sqrt(speed)
    float min_step_duration = 0.26f;       // s, fastest cadence
    float max_step_duration = 0.6f;        // s, slowest cadence (slow walk, turning in place)
    float walk_duty = 0.58f;               // fraction of a cycle each foot is down when walking (> 0.5; a fast walk uses less: duty_for)
    float run_duty = 0.36f;                // … when running (< 0.5: flight phase)
    float run_threshold = 1.9f;            // m/s: above it the gait runs
    float swing_clearance = 0.03f;         // m the swing sole keeps above the ground between its ends
    float spine_lean_deg_per_m_s = 4.0f;   // forward lean per unit speed
    float max_spine_lean_deg = 10.0f;
    float interpolation_rate = 8.0f;       // 1/s: lean, walk/run blend and pelvis height approach their targets
    float slope_speed_factor = 0.01f;      // speed reduction per degree of slope along the heading
    float turn_in_place_deg = 120.0f;      // reversals wider than this turn in place
    float stop_transition_s = 0.3f;        // the swing foot's time to plant after a stop, at most (longer only to keep it under 3 m/s)
    float max_step_height = 0.35f;         // m: a box rising more than this above the ground beside it is an obstacle
    float breath_amplitude = 0.005f;       // m of pelvis rise when idle
    float breath_period_s = 4.0f;
    GaitPrototypes walk = default_walk_prototypes();   // [gait.walk]
    GaitPrototypes run = default_run_prototypes();     // [gait.run]

};

}  // namespace marionette
