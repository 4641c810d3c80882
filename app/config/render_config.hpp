#pragma once
// Render settings file (config/render.toml): embedded defaults, then the user
// file. toml++ with file/line/key errors (ConfigError). Never part of SimConfig.
#include <string>
#include <string_view>
#include <vector>

#include "app/config/config.hpp"
#include "render_es/platform.hpp"
#include "render_es/settings.hpp"

namespace marionette {

struct RenderConfig {
    render::RenderSettings settings;
    std::string drm_device;
    render::KmsModeRequest kms;
    // Your own character (docs/render.md): `[render] character`, a .gltf/.glb
    // file drawn instead of the capsules ("" keeps the capsules), resolved against
    // the directory of the file that names it; `[character]` names skeleton roles
    // outright (role = "joint"), one entry per line of that table.
    std::string character;
    std::string character_origin;  // the render config file that named the map entries
    std::vector<std::pair<std::string, std::string>> character_map;
    std::vector<int> character_map_lines;
};

// Every key, as "table.key", with its documentation (docs/render.md lists each; a test checks).
std::vector<ConfigKeyInfo> render_config_schema();

RenderConfig apply_render_config_text(const RenderConfig& base, std::string_view toml_text, const std::string& file);
std::string_view default_render_config_text();
// Defaults, then the user file when the path is not empty. Throws ConfigError.
RenderConfig load_render_config(const std::string& user_file);

// "1920x1080" or "1920x1080@144" into the request; false when malformed.
bool parse_mode_text(std::string_view text, render::KmsModeRequest& request);

}  // namespace marionette
