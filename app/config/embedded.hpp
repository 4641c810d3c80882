#pragma once
// Files compiled into the binary (cmake/EmbedFiles.cmake), found by their path
// relative to the source root: the default config and the shipped programs, so
// the default demo runs from anywhere with no data beside it.
#include <string_view>

namespace marionette::embedded {
// Empty when no file of that path was embedded.
std::string_view find(std::string_view path);
}  // namespace marionette::embedded
