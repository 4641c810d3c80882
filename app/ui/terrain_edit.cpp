#include "app/ui/terrain_edit.hpp"

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "app/config/terrain_file.hpp"
#include "app/io/files.hpp"
#include "app/ui/toml_edit.hpp"

namespace marionette::ui {

namespace {

template <typename Feature>
void place(Feature& f, float x, float z, float side) {
    const float half = std::max(side, kMinFeatureSize) * 0.5f;
    f.min_x = x - half;
    f.max_x = x + half;
    f.min_z = z - half;
    f.max_z = z + half;
}

template <typename Feature>
std::optional<std::size_t> feature_at(const std::vector<Feature>& features, float x, float z) {
    // The last one listed wins a tie (what a person added last is on top).
    for (std::size_t i = features.size(); i-- > 0;) {
        const Feature& f = features[i];
        if (x >= f.min_x && x <= f.max_x && z >= f.min_z && z <= f.max_z) return i;
    }
    return std::nullopt;
}

template <typename Feature>
void shift(Feature& f, float dx, float dz) {
    f.min_x += dx;
    f.max_x += dx;
    f.min_z += dz;
    f.max_z += dz;
}

// One side from lo..hi grown by d about its centre, at least kMinFeatureSize.
void grow(float& lo, float& hi, float d) {
    const float centre = (lo + hi) * 0.5f;
    const float half = std::max((hi - lo) + d, kMinFeatureSize) * 0.5f;
    lo = centre - half;
    hi = centre + half;
    if (!(hi > lo)) hi = lo + kMinFeatureSize;  // far from the origin half a side may round away
}

}  // namespace

std::size_t add_box(Terrain& terrain, float x, float z, float side, float height) {
    TerrainBox b;
    place(b, x, z, side);
    b.top = query_ground(terrain, x, z).height + height;
    terrain.boxes.push_back(b);
    return terrain.boxes.size() - 1;
}

std::size_t add_slope(Terrain& terrain, float x, float z, float side, float height) {
    TerrainSlope s;
    place(s, x, z, side);
    s.base = query_ground(terrain, x, z).height + height;
    terrain.slopes.push_back(s);
    return terrain.slopes.size() - 1;
}

std::optional<std::size_t> box_at(const Terrain& terrain, float x, float z) { return feature_at(terrain.boxes, x, z); }
std::optional<std::size_t> slope_at(const Terrain& terrain, float x, float z) {
    return feature_at(terrain.slopes, x, z);
}

bool move_box(Terrain& terrain, std::size_t index, float dx, float dz, float dtop) {
    if (index >= terrain.boxes.size()) return false;
    shift(terrain.boxes[index], dx, dz);
    terrain.boxes[index].top += dtop;
    return true;
}

bool resize_box(Terrain& terrain, std::size_t index, float dx, float dz) {
    if (index >= terrain.boxes.size()) return false;
    grow(terrain.boxes[index].min_x, terrain.boxes[index].max_x, dx);
    grow(terrain.boxes[index].min_z, terrain.boxes[index].max_z, dz);
    return true;
}

bool delete_box(Terrain& terrain, std::size_t index) {
    if (index >= terrain.boxes.size()) return false;
    terrain.boxes.erase(terrain.boxes.begin() + static_cast<std::ptrdiff_t>(index));
    return true;
}

bool move_slope(Terrain& terrain, std::size_t index, float dx, float dz, float dbase) {
    if (index >= terrain.slopes.size()) return false;
    shift(terrain.slopes[index], dx, dz);
    terrain.slopes[index].base += dbase;
    return true;
}

bool resize_slope(Terrain& terrain, std::size_t index, float dx, float dz) {
    if (index >= terrain.slopes.size()) return false;
    grow(terrain.slopes[index].min_x, terrain.slopes[index].max_x, dx);
    grow(terrain.slopes[index].min_z, terrain.slopes[index].max_z, dz);
    return true;
}

bool tilt_slope(Terrain& terrain, std::size_t index, float dgx, float dgz) {
    if (index >= terrain.slopes.size()) return false;
    TerrainSlope& s = terrain.slopes[index];
    s.grade_x = std::clamp(s.grade_x + dgx, -kMaxGrade, kMaxGrade);
    s.grade_z = std::clamp(s.grade_z + dgz, -kMaxGrade, kMaxGrade);
    return true;
}

bool delete_slope(Terrain& terrain, std::size_t index) {
    if (index >= terrain.slopes.size()) return false;
    terrain.slopes.erase(terrain.slopes.begin() + static_cast<std::ptrdiff_t>(index));
    return true;
}

int brush_heightfield(Terrain& terrain, float x, float z, float radius, float delta) {
    Heightfield& hf = terrain.heightfield;
    if (hf.nx < 2 || hf.nz < 2) {
        const float half = kBrushCell * static_cast<float>(kBrushGridSide - 1) * 0.5f;
        hf.origin_x = x - half;
        hf.origin_z = z - half;
        hf.cell = kBrushCell;
        hf.nx = kBrushGridSide;
        hf.nz = kBrushGridSide;
        hf.heights.assign(static_cast<std::size_t>(kBrushGridSide) * kBrushGridSide, 0.0f);
    }
    int changed = 0;
    const float r2 = radius * radius;
    for (std::int32_t iz = 0; iz < hf.nz; ++iz) {
        const float pz = hf.origin_z + static_cast<float>(iz) * hf.cell - z;
        if (pz * pz > r2) continue;
        for (std::int32_t ix = 0; ix < hf.nx; ++ix) {
            const float px = hf.origin_x + static_cast<float>(ix) * hf.cell - x;
            if (px * px + pz * pz > r2) continue;
            hf.heights[static_cast<std::size_t>(iz) * static_cast<std::size_t>(hf.nx) + static_cast<std::size_t>(ix)] +=
                delta;
            ++changed;
        }
    }
    return changed;
}

std::string save_terrain_file(const Terrain& terrain, const std::string& path) {
    if (path.empty()) return "no file name";
    // The comment block at the top of the file it replaces stays (the data below
    // it are written anew, in serialize_terrain's order).
    std::string header;
    if (std::filesystem::exists(path)) {
        std::string old_text;
        try {
            old_text = read_text_file(path);
        } catch (const std::exception& e) {
            return std::string("not written: ") + e.what();  // names the file and why it cannot be read
        }
        std::istringstream old(old_text);
        for (std::string line; std::getline(old, line);) {
            const std::size_t first = line.find_first_not_of(" \t");
            if (first != std::string::npos && line[first] != '#') break;
            header += line + "\n";
        }
    }
    if (header.empty()) header = "# terrain, saved by the tuning UI's terrain editor (docs/ui.md)\n";
    const std::string text = header + serialize_terrain(terrain, "");
    try {
        (void)parse_terrain_text(text, path);  // never a file the next start would refuse
    } catch (const std::exception& e) {
        return std::string("not written, the result would not load: ") + e.what();
    }
    return write_replacing(path, text);  // beside it, then renamed over it (toml_edit.hpp)
}

}  // namespace marionette::ui
