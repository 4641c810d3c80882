#pragma once
// Steering (docs/gait.md, "Steering" and "Obstacles"): the law that moves the
// gait's root. The stick asks for a direction and a speed; obstacles clip that
// velocity; the heading turns toward it no faster than the lateral acceleration
// allows at the current speed; the speed is capped by how far the heading still
// has to turn (a sharp turn brakes, pivots, then accelerates), and near an
// obstacle by the distance left to stop in. The tick and the step planner's
// prediction run this same function, so a planned step lands where the root
// will be. Plain data, no allocation, det_math only.
#include <array>
#include <cstdint>

#include "runtime/gait/gait_config.hpp"
#include "runtime/ground/terrain.hpp"

namespace marionette {

inline constexpr int kMaxNearbyWalls = 8;
// m: the root stops this far from an obstacle face (toes, knees, hands and a
// leaning head stay outside it), and slides along faces at this distance.
inline constexpr float kWallStandOffM = 0.42f;

// Obstacle boxes near the root, nearest first: a box whose top is more than
// max_step_height above the ground outside its face nearest the root (and above
// the root's own ground), within the distance a full-speed approach and a
// predicted step need.
struct NearbyWalls {
    std::array<TerrainBox, kMaxNearbyWalls> boxes{};
    int count = 0;
};
NearbyWalls find_nearby_walls(const Terrain& terrain, const GaitConfig& c, vec3 root);

// What the stick asks: a unit direction in XZ (stick up is −Z), its heading
// (det::atan2 of the direction), and a speed (m/s, 0 when the stick is released).
struct SteerGoal {
    float dir_x = 0.0f;
    float dir_z = 1.0f;
    float heading = 0.0f;
    float speed = 0.0f;
};

// The root's motion state.
struct RootMotion {
    float x = 0.0f;
    float z = 0.0f;
    float heading = 0.0f;
    float speed = 0.0f;
    std::int32_t turning_in_place = 0;
    // The facing steer_root computed last, and for which heading: a prediction
    // steps the law tick by tick, mostly with an unchanged heading, and then
    // needs no new sine and cosine (the same bits either way). Not state: a
    // function of `heading`.
    bool facing_known = false;
    float facing_heading = 0.0f;
    float facing_x = 0.0f;
    float facing_z = 0.0f;
};

// What one step of the law aimed for, after the walls.
struct SteerResult {
    float heading = 0.0f;       // the direction aimed at: the stick's, or along a face it slid onto
    float goal_speed = 0.0f;    // the stick's speed after the walls
    float target_speed = 0.0f;  // … and after the turn cap: what the speed moved toward
    double diff = 0.0;          // heading aimed at − heading before the turn, wrapped
};

// The speeds of the law: braking deceleration and the speed at which the full
// turn rate is within the lateral acceleration.
float brake_deceleration(const GaitConfig& c);

// One tick of the law for a moving stick (goal.speed > 0): clips the goal
// against the walls at the root, updates turning in place, turns the heading,
// moves the speed toward its target, limits it by the walls along the new
// heading and moves the root.
SteerResult steer_root(RootMotion& m, const SteerGoal& goal, const NearbyWalls& walls, const GaitConfig& c, float dt);

// The root's whole move this tick (steering, the stance reach, an idle root
// settling between the feet), from (from_x, from_z) to (x, z), less what takes it
// further inside kWallStandOffM of a wall face than it was: the stand-off holds
// for every way the root moves, not only for the steered velocity.
void keep_root_out_of_walls(const NearbyWalls& walls, float from_x, float from_z, float& x, float& z);

}  // namespace marionette
