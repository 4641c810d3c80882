#pragma once
// The desired trajectory of motion matching: critically damped springs (as in
// Holden's "Spring-It-On", 2021) carry the character's simulated velocity toward
// the stick's velocity and its facing toward the stick's direction. The decay
// e^(−x) is the rational approximation 1 / (1 + x + 0.48x² + 0.235x³) (no libm
// transcendental: the tick stays bit-identical across libms), so the closed forms
// below are exact integrals of a spring whose decay is that function, and
// prediction at any time ahead is one evaluation, not a loop.
#include "runtime/math/math.hpp"

namespace marionette {

float approx_negexp(float x);

// Position, velocity and acceleration on the ground plane (x, z), and a facing
// angle with its rate.
struct TrajectorySpring {
    float px = 0.0f, pz = 0.0f;
    float vx = 0.0f, vz = 0.0f;
    float ax = 0.0f, az = 0.0f;
    float heading = 0.0f, heading_rate = 0.0f;
};

struct TrajectoryGoal {
    float vx = 0.0f, vz = 0.0f;   // desired velocity, m/s
    float heading = 0.0f;         // desired facing, radians
};

// The spring `dt` seconds later (dt ≥ 0), halflives in seconds (> 0).
TrajectorySpring advance_trajectory(const TrajectorySpring& s, const TrajectoryGoal& goal, float velocity_halflife,
                                    float heading_halflife, float dt);

}  // namespace marionette
