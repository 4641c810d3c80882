#include "runtime/ground/obstacles.hpp"

namespace marionette {

float box_rise_at(const Terrain& terrain, const TerrainBox& box, float edge_x, float edge_z, float normal_x, float normal_z) {
    const float x = edge_x + normal_x * kObstacleFaceProbeM;
    const float z = edge_z + normal_z * kObstacleFaceProbeM;
    return box.top - query_ground(terrain, x, z).height;
}

namespace {

// The depth of p in one box that holds it, or 0 (see obstacle_depth).
float depth_in_box(const Terrain& terrain, const TerrainBox& b, vec3 p, float max_step_height) {
    struct Face {
        float distance;   // from p to the face, horizontally
        float x, z;       // p projected onto the face
        float nx, nz;     // outward normal
    };
    const Face faces[4] = {{p.x - b.min_x, b.min_x, p.z, -1.0f, 0.0f},
                           {b.max_x - p.x, b.max_x, p.z, 1.0f, 0.0f},
                           {p.z - b.min_z, p.x, b.min_z, 0.0f, -1.0f},
                           {b.max_z - p.z, p.x, b.max_z, 0.0f, 1.0f}};
    float nearest = faces[0].distance;
    for (const Face& f : faces) nearest = f.distance < nearest ? f.distance : nearest;
    float nearest_wall = -1.0f;
    for (const Face& f : faces) {
        if (nearest_wall >= 0.0f && f.distance >= nearest_wall) continue;
        if (box_rise_at(terrain, b, f.x, f.z, f.nx, f.nz) > max_step_height) nearest_wall = f.distance;
    }
    // No obstacle face, or p is nearer a step face than any obstacle face.
    if (nearest_wall < 0.0f || nearest < nearest_wall) return 0.0f;
    const float below_top = b.top - p.y;
    return below_top < nearest_wall ? below_top : nearest_wall;
}

}  // namespace

float obstacle_depth(const Terrain& terrain, vec3 p, float max_step_height) {
    float deepest = 0.0f;
    for (const TerrainBox& b : terrain.boxes) {
        if (!(p.x > b.min_x && p.x < b.max_x && p.z > b.min_z && p.z < b.max_z && p.y < b.top)) continue;
        const float d = depth_in_box(terrain, b, p, max_step_height);
        deepest = d > deepest ? d : deepest;
    }
    return deepest;
}

}  // namespace marionette
