#pragma once
// The render config's character (docs/render.md "Your own character"): loads
// `[render] character` with the `[character]` role map, for the puppet skeleton.
#include <memory>

#include "app/config/render_config.hpp"
#include "render_es/mesh.hpp"
#include "runtime/anim/skeleton.hpp"

namespace marionette {

// Null when `[render] character` is empty (the capsule puppet). Throws
// ImportError naming the glTF file (or ConfigError naming a bad map entry).
std::shared_ptr<const render::SkinnedMesh> load_render_character(const RenderConfig& config, const Skeleton& puppet);

}  // namespace marionette
