#pragma once
// Obstacles (docs/gait.md, "Obstacles"): a terrain box is an obstacle where its
// top stands more than max_step_height above the ground just outside its face,
// so a staircase (each step a box a riser above the one before) is not one, but
// a wall on flat ground is. The gait keeps the puppet out of them and
// `gait-eval` measures how deep any joint went into one, with this one
// definition. Pure functions of the terrain, no allocation.
#include "runtime/ground/terrain.hpp"

namespace marionette {

// How far outside a face the ground beside it is sampled (m).
inline constexpr float kObstacleFaceProbeM = 0.02f;

// The box's rise above the ground just outside its footprint at the edge point
// (edge_x, edge_z), whose outward horizontal normal is (normal_x, normal_z).
float box_rise_at(const Terrain& terrain, const TerrainBox& box, float edge_x, float edge_z, float normal_x, float normal_z);

// How far p is inside an obstacle, metres (0 when in none): for each box that
// holds p (inside its footprint, below its top) whose nearest side face is an
// obstacle face there (rise above the ground outside it, at p's place along the
// face, more than max_step_height), the distance to the nearest way out through
// such a face or the top; the deepest over the boxes. A point that entered a box
// through a face that is only a step (a riser) is ground penetration, not this.
float obstacle_depth(const Terrain& terrain, vec3 p, float max_step_height);

}  // namespace marionette
