#pragma once
// What the importers and their callers read from a file's path: the clip name
// and the lower-case extension that says which importer to use.
#include <string>

namespace marionette {

// "dir/walk.bvh" → "walk"; both separators, since names may come from Windows.
std::string clip_name_from_path(const std::string& path);

// "dir/Walk.BVH" → "bvh"; "" when the last path part has no '.'.
std::string lower_extension(const std::string& path);

}  // namespace marionette
