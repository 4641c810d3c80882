#pragma once
// The ground the puppet walks on: an optional heightfield, plus axis-aligned boxes
// (steps, platforms) and planar slope patches on top of it. Plain data; the query
// is a pure function, so the gait, the renderer and the tests all see the same
// surface. Up is +Y; heights are metres. Loading from TOML (with file/line/key
// errors) lives in app/, since runtime/ reads no files.
#include <array>
#include <cstdint>
#include <vector>

#include "runtime/math/math.hpp"

namespace marionette {

// Regular grid of heights, row-major in z then x: heights[iz * nx + ix] is the
// height at (origin_x + ix * cell, origin_z + iz * cell). Bilinear in between;
// outside the grid the nearest edge value holds. Empty (nx or nz < 2): height 0.
struct Heightfield {
    float origin_x = 0.0f;
    float origin_z = 0.0f;
    float cell = 1.0f;
    std::int32_t nx = 0;
    std::int32_t nz = 0;
    std::vector<float> heights;
    friend bool operator==(const Heightfield&, const Heightfield&) = default;
};

// A solid box standing on the ground from below: inside its XZ footprint the
// surface is at least `top`.
struct TerrainBox {
    float min_x = 0.0f;
    float min_z = 0.0f;
    float max_x = 0.0f;
    float max_z = 0.0f;
    float top = 0.0f;
    friend bool operator==(const TerrainBox&, const TerrainBox&) = default;
};

// A planar patch: inside its footprint the surface is at least
// base + grade_x * (x - min_x) + grade_z * (z - min_z) (grades are rise/run).
struct TerrainSlope {
    float min_x = 0.0f;
    float min_z = 0.0f;
    float max_x = 0.0f;
    float max_z = 0.0f;
    float base = 0.0f;
    float grade_x = 0.0f;
    float grade_z = 0.0f;
    friend bool operator==(const TerrainSlope&, const TerrainSlope&) = default;
};

struct Terrain {
    Heightfield heightfield;
    std::vector<TerrainBox> boxes;
    std::vector<TerrainSlope> slopes;
    friend bool operator==(const Terrain&, const Terrain&) = default;
};

struct GroundSample {
    float height = 0.0f;
    vec3 normal{0.0f, 1.0f, 0.0f};  // unit; straight up on box tops and flat ground
};

// Surface height and normal at (x, z): the highest of heightfield, boxes and
// slopes there. Cost is linear in the number of boxes and slopes.
GroundSample query_ground(const Terrain& terrain, float x, float z);

// Highest surface point on the straight segment (x0, z0)–(x1, z1), sampled every
// `step` metres and at both ends: what a swing foot must clear.
float max_height_along(const Terrain& terrain, float x0, float z0, float x1, float z1, float step);

// The boxes of a terrain that overlap a rectangle, gathered once for many ground
// queries inside it (a swing path's ~800 queries scanned every box of the
// terrain each): query_ground and max_height_along on a window give exactly
// what they give on its terrain, at any point. A point inside the rectangle
// scans only the gathered boxes (every box holding such a point overlaps the
// rectangle; the boxes keep their order, so ties resolve as before), any other
// point, or a window that overflowed kMaxWindowBoxes, scans the whole terrain.
// The terrain must outlive the window and stay unchanged while it is used.
inline constexpr int kMaxWindowBoxes = 64;
struct GroundWindow {
    const Terrain* terrain = nullptr;
    float min_x = 0.0f, min_z = 0.0f, max_x = 0.0f, max_z = 0.0f;
    bool overflow = false;  // more boxes overlap than fit: every query scans the terrain
    // No box, slope or heightfield reaches the rectangle: a point inside it is
    // on the level ground at 0 (what the full query gives there), with no scan.
    bool level = false;
    int count = 0;
    std::array<std::uint32_t, kMaxWindowBoxes> boxes{};  // indices into terrain->boxes, ascending
};
GroundWindow ground_window(const Terrain& terrain, float min_x, float min_z, float max_x, float max_z);
GroundSample query_ground(const GroundWindow& window, float x, float z);
float max_height_along(const GroundWindow& window, float x0, float z0, float x1, float z1, float step);

}  // namespace marionette
