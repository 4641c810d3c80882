#include "runtime/ground/terrain.hpp"

#include <algorithm>
#include <cmath>

namespace marionette {

namespace {

struct Surface {
    float height;
    vec3 normal;
};

// Whether the heightfield holds a grid (else it reads level ground at 0).
bool heightfield_valid(const Heightfield& hf) {
    return !(hf.nx < 2 || hf.nz < 2 || hf.heights.size() < static_cast<std::size_t>(hf.nx) * static_cast<std::size_t>(hf.nz) ||
             !(hf.cell > 0.0f));
}

[[gnu::always_inline]] inline Surface heightfield_at(const Heightfield& hf, float x, float z) {
    if (!heightfield_valid(hf)) return {0.0f, vec3(0.0f, 1.0f, 0.0f)};
    const float max_u = static_cast<float>(hf.nx - 1);
    const float max_v = static_cast<float>(hf.nz - 1);
    // A NaN coordinate reads the grid's first row or column (clamped like a
    // point off the grid): converting a NaN to int indexed outside the heights.
    const float raw_u = (x - hf.origin_x) / hf.cell, raw_v = (z - hf.origin_z) / hf.cell;
    const float u = std::isnan(raw_u) ? 0.0f : std::clamp(raw_u, 0.0f, max_u);
    const float v = std::isnan(raw_v) ? 0.0f : std::clamp(raw_v, 0.0f, max_v);
    const int ix = std::min(static_cast<int>(u), hf.nx - 2);
    const int iz = std::min(static_cast<int>(v), hf.nz - 2);
    const float fu = u - static_cast<float>(ix);
    const float fv = v - static_cast<float>(iz);
    const auto at = [&](int i, int k) { return hf.heights[static_cast<std::size_t>(k) * static_cast<std::size_t>(hf.nx) + static_cast<std::size_t>(i)]; };
    const float h00 = at(ix, iz), h10 = at(ix + 1, iz), h01 = at(ix, iz + 1), h11 = at(ix + 1, iz + 1);
    const float h0 = h00 + (h10 - h00) * fu;
    const float h1 = h01 + (h11 - h01) * fu;
    const float height = h0 + (h1 - h0) * fv;
    // Gradient of the bilinear patch; flat outside the grid (the value is clamped there).
    const bool inside_x = (x - hf.origin_x) / hf.cell > 0.0f && (x - hf.origin_x) / hf.cell < max_u;
    const bool inside_z = (z - hf.origin_z) / hf.cell > 0.0f && (z - hf.origin_z) / hf.cell < max_v;
    const float dhdx = inside_x ? ((h10 - h00) * (1.0f - fv) + (h11 - h01) * fv) / hf.cell : 0.0f;
    const float dhdz = inside_z ? ((h01 - h00) * (1.0f - fu) + (h11 - h10) * fu) / hf.cell : 0.0f;
    const vec3 n(-dhdx, 1.0f, -dhdz);
    const float len = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
    return {height, n / len};
}

bool inside(float x, float z, float min_x, float min_z, float max_x, float max_z) {
    return x >= min_x && x <= max_x && z >= min_z && z <= max_z;
}

// The heightfield and the slopes at (x, z): every query's surface before its boxes.
[[gnu::always_inline]] inline Surface surface_below_boxes(const Terrain& terrain, float x, float z) {
    Surface best = heightfield_at(terrain.heightfield, x, z);
    for (const TerrainSlope& s : terrain.slopes) {
        if (!inside(x, z, s.min_x, s.min_z, s.max_x, s.max_z)) continue;
        const float h = s.base + s.grade_x * (x - s.min_x) + s.grade_z * (z - s.min_z);
        if (h > best.height) {
            const vec3 n(-s.grade_x, 1.0f, -s.grade_z);
            best = {h, n / std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z)};
        }
    }
    return best;
}

[[gnu::always_inline]] inline void raise_to_box(Surface& best, const TerrainBox& b, float x, float z) {
    if (inside(x, z, b.min_x, b.min_z, b.max_x, b.max_z) && b.top > best.height) best = {b.top, vec3(0.0f, 1.0f, 0.0f)};
}

// The sampling of max_height_along, for either kind of query.
template <class Query>
float highest_along(const Query& query, float x0, float z0, float x1, float z1, float step) {
    const float dx = x1 - x0;
    const float dz = z1 - z0;
    const float length = std::sqrt(dx * dx + dz * dz);
    const int samples = (step > 0.0f && length > 0.0f) ? std::min(4096, static_cast<int>(length / step) + 1) : 1;
    float highest = std::max(query(x0, z0), query(x1, z1));
    for (int i = 1; i < samples; ++i) {
        const float t = static_cast<float>(i) / static_cast<float>(samples);
        highest = std::max(highest, query(x0 + dx * t, z0 + dz * t));
    }
    return highest;
}

}  // namespace

GroundSample query_ground(const Terrain& terrain, float x, float z) {
    Surface best = surface_below_boxes(terrain, x, z);
    for (const TerrainBox& b : terrain.boxes) raise_to_box(best, b, x, z);
    return {best.height, best.normal};
}

float max_height_along(const Terrain& terrain, float x0, float z0, float x1, float z1, float step) {
    return highest_along([&](float x, float z) { return query_ground(terrain, x, z).height; }, x0, z0, x1, z1, step);
}

GroundWindow ground_window(const Terrain& terrain, float min_x, float min_z, float max_x, float max_z) {
    GroundWindow w;
    w.terrain = &terrain;
    w.min_x = min_x, w.min_z = min_z, w.max_x = max_x, w.max_z = max_z;
    for (std::size_t i = 0; i < terrain.boxes.size(); ++i) {
        const TerrainBox& b = terrain.boxes[i];
        // Overlap with the rectangle, closed on every side as inside() is. A
        // box with a NaN bound holds no point, overlapping or not.
        if (!(b.max_x >= min_x && b.min_x <= max_x && b.max_z >= min_z && b.min_z <= max_z)) continue;
        if (w.count == kMaxWindowBoxes || i > UINT32_MAX) {
            w.overflow = true;
            break;
        }
        w.boxes[static_cast<std::size_t>(w.count++)] = static_cast<std::uint32_t>(i);
    }
    bool slope_overlaps = false;
    for (const TerrainSlope& s : terrain.slopes)
        slope_overlaps = slope_overlaps || !(s.max_x < min_x || s.min_x > max_x || s.max_z < min_z || s.min_z > max_z);
    w.level = !w.overflow && w.count == 0 && !slope_overlaps && !heightfield_valid(terrain.heightfield);
    return w;
}

namespace {
[[gnu::always_inline]] inline Surface surface_in_window(const GroundWindow& w, float x, float z) {
    if (w.level && inside(x, z, w.min_x, w.min_z, w.max_x, w.max_z)) return {0.0f, vec3(0.0f, 1.0f, 0.0f)};
    const Terrain& terrain = *w.terrain;
    Surface best = surface_below_boxes(terrain, x, z);
    // Every box gathered (a flat terrain: none at all): the terrain's own list, with no point test.
    const bool all = !w.overflow && static_cast<std::size_t>(w.count) == terrain.boxes.size();
    if (all || w.overflow || !inside(x, z, w.min_x, w.min_z, w.max_x, w.max_z)) {
        for (const TerrainBox& b : terrain.boxes) raise_to_box(best, b, x, z);
        return best;
    }
    for (int k = 0; k < w.count; ++k) raise_to_box(best, terrain.boxes[w.boxes[static_cast<std::size_t>(k)]], x, z);
    return best;
}
}  // namespace

GroundSample query_ground(const GroundWindow& w, float x, float z) {
    const Surface best = surface_in_window(w, x, z);
    return {best.height, best.normal};
}

float max_height_along(const GroundWindow& window, float x0, float z0, float x1, float z1, float step) {
    return highest_along([&](float x, float z) { return surface_in_window(window, x, z).height; }, x0, z0, x1, z1, step);
}

}  // namespace marionette
