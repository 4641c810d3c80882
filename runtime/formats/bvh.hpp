#pragma once
// BVH (Biovision hierarchy) import and export.
// Conventions: angles in degrees; rotation channels compose in the order listed
// (`Zrotation Xrotation Yrotation` ⇒ R = Rz·Rx·Ry on column vectors); position
// channels, on any joint, replace that joint's OFFSET.
#include <string>
#include <string_view>

#include "runtime/anim/clip.hpp"
#include "runtime/errors/import_error.hpp"

namespace marionette {

// Parses BVH text. `file_name` is used in error messages only.
// Throws ImportError (file, line, what was expected) on any malformed input.
Clip import_bvh(std::string_view text, const std::string& file_name);

// Reads and parses a file; the clip is named after the file without extension.
Clip load_bvh_file(const std::string& path);

// Writes a BVH that imports back to the same poses: every joint gets
// `Zrotation Xrotation Yrotation`, and joints with animated translation (always
// the roots) get `Xposition Yposition Zposition` first. Numbers are printed with
// enough digits that the round trip holds to 1e-4 degrees / 1e-5 units.
std::string export_bvh(const Clip& clip);

}  // namespace marionette
