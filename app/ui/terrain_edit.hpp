#pragma once
// The terrain editor's model (docs/ui.md, "Terrain editor"): edits of a Terrain
// that always leave it loadable from a terrain file (parse_terrain_text takes
// what serialize_terrain writes of it, bit for bit): boxes and slope patches
// added, moved, resized and deleted, heightfield cells raised and lowered with a
// round brush. Plain functions on plain data; the UI calls them, Save writes
// the result with save_terrain_file.
#include <cstddef>
#include <optional>
#include <string>

#include "runtime/ground/terrain.hpp"

namespace marionette::ui {

inline constexpr float kMinFeatureSize = 0.05f;  // m: the smallest box or slope side an edit leaves
inline constexpr float kMaxGrade = 2.0f;         // rise/run, as terrain files allow
inline constexpr float kBrushCell = 0.25f;       // m: grid spacing of a heightfield the brush creates
inline constexpr int kBrushGridSide = 81;        // points per side of that grid (20 m)

// A box of `side` × `side` metres centred on (x, z), its top `height` above the
// ground there. Returns its index.
std::size_t add_box(Terrain& terrain, float x, float z, float side, float height);
// A flat slope patch (grades 0) like add_box's box, its base `height` above the ground.
std::size_t add_slope(Terrain& terrain, float x, float z, float side, float height);

// The topmost box whose footprint holds (x, z); none when no box does.
std::optional<std::size_t> box_at(const Terrain& terrain, float x, float z);
std::optional<std::size_t> slope_at(const Terrain& terrain, float x, float z);

// False (nothing changes) for an index out of range.
bool move_box(Terrain& terrain, std::size_t index, float dx, float dz, float dtop);
// Grows (or shrinks) each side by dx, dz about the centre; a side never goes
// below kMinFeatureSize.
bool resize_box(Terrain& terrain, std::size_t index, float dx, float dz);
bool delete_box(Terrain& terrain, std::size_t index);

bool move_slope(Terrain& terrain, std::size_t index, float dx, float dz, float dbase);
bool resize_slope(Terrain& terrain, std::size_t index, float dx, float dz);
// Changes the grades by dgx, dgz, kept within ±kMaxGrade.
bool tilt_slope(Terrain& terrain, std::size_t index, float dgx, float dgz);
bool delete_slope(Terrain& terrain, std::size_t index);

// Raises (delta > 0) or lowers every heightfield point within `radius` of
// (x, z) by delta. Without a heightfield, one of kBrushGridSide² points
// kBrushCell apart, all 0, is first made centred on (x, z). Returns the number
// of points changed.
int brush_heightfield(Terrain& terrain, float x, float z, float radius, float delta);

// Writes the terrain as a terrain file to `path` (beside it, then renamed over
// it), keeping the comment lines at the top of the file it replaces. Empty
// string: written; otherwise why not.
std::string save_terrain_file(const Terrain& terrain, const std::string& path);

}  // namespace marionette::ui
