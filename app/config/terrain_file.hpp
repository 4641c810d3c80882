#pragma once
// Terrain descriptions in TOML (docs/terrain.md): a heightfield grid, boxes
// (steps, platforms) and planar slopes, loaded into runtime::Terrain with errors
// that name the file, line, key and what was expected (ConfigError, exit 2).
//
// The same tables appear in three places: a terrain file (top level), the
// `[terrain]` table of a configuration (inline data), and the effective
// configuration embedded in every input log (always inline, so a replay walks on
// exactly the recorded ground whatever files exist where it runs).
#include <string>
#include <string_view>

#include <toml++/toml.h>

#include "runtime/ground/terrain.hpp"

namespace marionette {

// The terrains compiled into the binary: config/terrain/NAME.toml.
inline constexpr const char* kBuiltinTerrains[] = {"flat",     "stairs",          "slope",    "rubble",
                                                   "building_stairs", "hillside", "wall"};

// "flat, stairs, …, wall": the built-in names, for messages.
std::string builtin_terrain_list();

// Parses terrain TOML text. `file_name` is used in error messages.
Terrain parse_terrain_text(std::string_view toml_text, const std::string& file_name);

// Reads a terrain from `heightfield`, `box` and `slope` entries of a parsed table
// (a terrain file's root or a configuration's [terrain]). `key_prefix` is put in
// front of key names in error messages ("terrain." for a configuration).
Terrain terrain_from_table(const toml::table& table, const std::string& file_name, const std::string& key_prefix);

// True when the table holds terrain data (any of heightfield, box, slope).
bool table_has_terrain_data(const toml::table& table);

// A built-in name ("stairs" or "builtin:stairs") or a file path.
Terrain load_terrain(const std::string& spec);

// The terrain as TOML tables under `table_prefix` ("" for a file, "terrain." for
// a configuration); floats print so they read back to the same bits.
std::string serialize_terrain(const Terrain& terrain, const std::string& table_prefix);

}  // namespace marionette
