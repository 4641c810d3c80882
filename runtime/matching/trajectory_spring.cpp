#include "runtime/matching/trajectory_spring.hpp"

#include "runtime/math/det_math.hpp"

namespace marionette {

float approx_negexp(float x) { return 1.0f / (1.0f + x + 0.48f * x * x + 0.235f * x * x * x); }

namespace {
constexpr float kLn2 = 0.69314718f;

// One axis of a velocity spring that also integrates position.
void velocity_axis(float& x, float& v, float& a, float goal, float y, float dt) {
    const float j0 = v - goal;
    const float j1 = a + j0 * y;
    const float e = approx_negexp(y * dt);
    x = e * (((-j1) / (y * y)) + ((-j0 - j1 * dt) / y)) + (j1 / (y * y)) + j0 / y + goal * dt + x;
    v = e * (j0 + j1 * dt) + goal;
    a = e * (a - j1 * y * dt);
}
}  // namespace

TrajectorySpring advance_trajectory(const TrajectorySpring& s, const TrajectoryGoal& goal, float velocity_halflife,
                                    float heading_halflife, float dt) {
    TrajectorySpring r = s;
    const float yv = 2.0f * kLn2 / velocity_halflife;  // half the damping of a critically damped spring
    velocity_axis(r.px, r.vx, r.ax, goal.vx, yv, dt);
    velocity_axis(r.pz, r.vz, r.az, goal.vz, yv, dt);
    const float yh = 2.0f * kLn2 / heading_halflife;
    const float j0 = static_cast<float>(det::wrap_angle(static_cast<double>(s.heading) - goal.heading));
    const float j1 = s.heading_rate + j0 * yh;
    const float e = approx_negexp(yh * dt);
    r.heading = static_cast<float>(det::wrap_angle(static_cast<double>(e * (j0 + j1 * dt)) + goal.heading));
    r.heading_rate = e * (s.heading_rate - j1 * yh * dt);
    return r;
}

}  // namespace marionette
