#include "runtime/gait/steering.hpp"

#include <cmath>
#include <cstring>

#include "runtime/ground/obstacles.hpp"
#include "runtime/math/det_math.hpp"

namespace marionette {

namespace {

// The law's constants (docs/gait.md, "Steering").
constexpr float kLateralAccelerationM_s2 = 6.0f;   // the heading turns at most this / speed (rad/s)
constexpr float kMinBrakeM_s2 = 8.0f;              // braking is at least this hard (or `acceleration`)
constexpr double kFreeTurnDeg = 30.0;              // a turn this small keeps the commanded speed
constexpr double kPivotTurnDeg = 90.0;             // … from here on the speed is at most the pivot speed
constexpr double kEndTurnInPlaceDeg = 20.0;        // a turn in place ends once the aim is this close to the heading
constexpr float kMinSlideShare = 0.25f;            // a clipped goal slower than this share of the stick's: stand
constexpr float kWallProbeHorizonS = 0.8f;         // s of travel at max_speed the wall search looks ahead
constexpr float kNoWallM = 1e9f;

float clampf(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }
double clamp_magnitude(double v, double limit) { return v > limit ? limit : (v < -limit ? -limit : v); }

// The point of the box's footprint nearest (x, z), the distance to it and the
// outward direction from it (zero inside the footprint).
struct Nearest {
    float x, z;
    float distance;
    float nx, nz;
};
Nearest nearest_on_box(const TerrainBox& b, float x, float z) {
    Nearest n{clampf(x, b.min_x, b.max_x), clampf(z, b.min_z, b.max_z), 0.0f, 0.0f, 0.0f};
    const float dx = x - n.x, dz = z - n.z;
    n.distance = std::sqrt(dx * dx + dz * dz);
    if (n.distance > 0.0f) {
        n.nx = dx / n.distance;
        n.nz = dz / n.distance;
    }
    return n;
}

// The fastest the root may close on a face `gap` metres beyond the stand-off
// distance: what braking can still stop in.
float approach_limit(float gap, float brake) { return gap > 0.0f ? std::sqrt(2.0f * brake * gap) : 0.0f; }

// Removes from (vx, vz) the part toward each wall, seen from (x, z), beyond
// allowed(distance to the wall); true when anything was removed. Twice over
// the walls, for inside corners.
template <class Allowed>
bool clip_toward_walls(float& vx, float& vz, const NearbyWalls& walls, float x, float z, Allowed allowed) {
    bool clipped = false;
    for (int pass = 0; pass < 2; ++pass)
        for (int i = 0; i < walls.count; ++i) {
            const Nearest n = nearest_on_box(walls.boxes[static_cast<std::size_t>(i)], x, z);
            if (n.distance <= 0.0f) continue;
            const float most = allowed(n.distance);
            const float toward = -(vx * n.nx + vz * n.nz);
            if (toward > most) {
                vx += n.nx * (toward - most);
                vz += n.nz * (toward - most);
                clipped = true;
            }
        }
    return clipped;
}

// Removes from (vx, vz) what approaches any wall faster than it can stop; true when anything was removed.
bool clip_against_walls(float& vx, float& vz, const NearbyWalls& walls, float x, float z, float brake) {
    return clip_toward_walls(vx, vz, walls, x, z,
                             [brake](float distance) { return approach_limit(distance - kWallStandOffM, brake); });
}

// The speed along `forward` that approaches no wall faster than it can stop.
float wall_speed_limit(const NearbyWalls& walls, float x, float z, float fx, float fz, float brake) {
    float limit = kNoWallM;
    for (int i = 0; i < walls.count; ++i) {
        const Nearest n = nearest_on_box(walls.boxes[static_cast<std::size_t>(i)], x, z);
        if (n.distance <= 0.0f) continue;
        const float toward = -(fx * n.nx + fz * n.nz);
        if (toward <= 1e-6f) continue;
        const float allowed = approach_limit(n.distance - kWallStandOffM, brake) / toward;
        limit = allowed < limit ? allowed : limit;
    }
    return limit;
}

// The speed from which the full turn rate stays within the lateral acceleration.
float pivot_speed(const GaitConfig& c) {
    return kLateralAccelerationM_s2 / static_cast<float>(c.turn_rate_deg_s * det::kDegToRad);
}

// The most speed a turn of abs_diff radians still to go allows: all of it up to
// kFreeTurnDeg, falling to the pivot speed at kPivotTurnDeg, none past
// turn_in_place_deg (the puppet brakes, then turns in place).
float turn_speed_cap(double abs_diff, float goal_speed, const GaitConfig& c) {
    const double free = kFreeTurnDeg * det::kDegToRad, pivot = kPivotTurnDeg * det::kDegToRad;
    if (abs_diff <= free) return goal_speed;
    if (abs_diff > c.turn_in_place_deg * det::kDegToRad) return 0.0f;
    const float slow = goal_speed < pivot_speed(c) ? goal_speed : pivot_speed(c);
    if (abs_diff >= pivot) return slow;
    const float w = static_cast<float>((abs_diff - free) / (pivot - free));
    return goal_speed + (slow - goal_speed) * w;
}

}  // namespace

void keep_root_out_of_walls(const NearbyWalls& walls, float from_x, float from_z, float& x, float& z) {
    float dx = x - from_x, dz = z - from_z;
    clip_toward_walls(dx, dz, walls, from_x, from_z,
                      [](float distance) { return distance > kWallStandOffM ? distance - kWallStandOffM : 0.0f; });
    x = from_x + dx;
    z = from_z + dz;
}

float brake_deceleration(const GaitConfig& c) { return c.acceleration > kMinBrakeM_s2 ? c.acceleration : kMinBrakeM_s2; }

NearbyWalls find_nearby_walls(const Terrain& terrain, const GaitConfig& c, vec3 root) {
    NearbyWalls out;
    std::array<float, kMaxNearbyWalls> distance{};
    const float reach = kWallStandOffM + c.max_speed * c.max_speed / (2.0f * brake_deceleration(c)) +
                        c.max_speed * kWallProbeHorizonS;
    for (const TerrainBox& b : terrain.boxes) {
        if (b.top - root.y <= c.max_step_height) continue;  // a step even from where the puppet stands
        const Nearest n = nearest_on_box(b, root.x, root.z);
        if (n.distance <= 0.0f || n.distance > reach) continue;  // standing on it, or far
        if (out.count == kMaxNearbyWalls && n.distance >= distance[kMaxNearbyWalls - 1]) continue;
        if (box_rise_at(terrain, b, n.x, n.z, n.nx, n.nz) <= c.max_step_height) continue;
        // Insert, nearest first (a full list drops its farthest).
        int at = out.count < kMaxNearbyWalls ? out.count++ : kMaxNearbyWalls - 1;
        while (at > 0 && distance[static_cast<std::size_t>(at - 1)] > n.distance) {
            out.boxes[static_cast<std::size_t>(at)] = out.boxes[static_cast<std::size_t>(at - 1)];
            distance[static_cast<std::size_t>(at)] = distance[static_cast<std::size_t>(at - 1)];
            --at;
        }
        out.boxes[static_cast<std::size_t>(at)] = b;
        distance[static_cast<std::size_t>(at)] = n.distance;
    }
    return out;
}

SteerResult steer_root(RootMotion& m, const SteerGoal& goal, const NearbyWalls& walls, const GaitConfig& c, float dt) {
    const float brake = brake_deceleration(c);
    SteerResult r;
    r.heading = goal.heading;
    r.goal_speed = goal.speed;
    float vx = goal.dir_x * goal.speed, vz = goal.dir_z * goal.speed;
    if (clip_against_walls(vx, vz, walls, m.x, m.z, brake)) {
        const float clipped = std::sqrt(vx * vx + vz * vz);
        if (clipped < kMinSlideShare * goal.speed) {
            r.goal_speed = 0.0f;  // pushing into the face: stand, facing the stick
        } else {
            r.goal_speed = clipped;  // slide along the face
            r.heading = static_cast<float>(det::atan2(vx, vz));
        }
    }
    r.diff = det::wrap_angle(static_cast<double>(r.heading) - m.heading);
    const double abs_diff = r.diff < 0 ? -r.diff : r.diff;
    // A wide reversal turns in place at once from a walk, and from a run once braked to walking speed.
    if (abs_diff > c.turn_in_place_deg * det::kDegToRad && m.speed <= c.run_threshold) m.turning_in_place = 1;
    else if (abs_diff < kEndTurnInPlaceDeg * det::kDegToRad) m.turning_in_place = 0;
    // The heading: at the turn rate, and no faster than the lateral acceleration allows at this speed.
    const double turn_rate = c.turn_rate_deg_s * det::kDegToRad;
    double rate = turn_rate;
    if (!m.turning_in_place && m.speed * turn_rate > kLateralAccelerationM_s2) rate = kLateralAccelerationM_s2 / m.speed;
    m.heading = static_cast<float>(det::wrap_angle(m.heading + clamp_magnitude(r.diff, rate * dt)));
    // The speed: none while turning in place, else toward the goal capped by the turn still to go.
    r.target_speed = m.turning_in_place ? 0.0f : turn_speed_cap(abs_diff, r.goal_speed, c);
    if (m.turning_in_place) {
        m.speed = 0.0f;
    } else if (r.target_speed > m.speed) {
        const float up = c.acceleration * dt;
        m.speed = r.target_speed - m.speed > up ? m.speed + up : r.target_speed;
    } else {
        const float down = brake * dt;
        m.speed = m.speed - r.target_speed > down ? m.speed - down : r.target_speed;
    }
    if (!m.facing_known || std::memcmp(&m.facing_heading, &m.heading, sizeof m.heading) != 0) {
        double s = 0.0, co = 0.0;
        det::sin_cos(m.heading, s, co);
        m.facing_known = true;
        m.facing_heading = m.heading;
        m.facing_x = static_cast<float>(s);
        m.facing_z = static_cast<float>(co);
    }
    const float fx = m.facing_x, fz = m.facing_z;
    const float limit = wall_speed_limit(walls, m.x, m.z, fx, fz, brake);
    if (m.speed > limit) m.speed = limit;
    m.x += fx * m.speed * dt;
    m.z += fz * m.speed * dt;
    return r;
}

}  // namespace marionette
