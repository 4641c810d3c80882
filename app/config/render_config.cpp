#include "app/config/render_config.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <functional>

#include "app/config/embedded.hpp"
#include "app/io/files.hpp"
#include "retarget/humanoid.hpp"
#include "runtime/errors/outcome.hpp"

namespace marionette {

namespace {
enum class Kind { integer, number, boolean, colour, text };

struct RenderKey {
    const char* table;
    const char* key;
    Kind kind;
    double min;
    double max;
    const char* doc;
    // Stores the validated value; `text` carries strings, `number` numbers and
    // booleans (0/1), `colour` colours. Fails saying what was expected.
    std::function<Outcome(RenderConfig&, double number, const vec3& colour, const std::string& text)> set;
};

using S = render::RenderSettings;
auto int_field(std::int32_t S::*f) {
    return [f](RenderConfig& c, double v, const vec3&, const std::string&) { c.settings.*f = static_cast<std::int32_t>(v); return Outcome::success(); };
}
auto bool_field(bool S::*f) {
    return [f](RenderConfig& c, double v, const vec3&, const std::string&) { c.settings.*f = v != 0.0; return Outcome::success(); };
}
auto colour_field(vec3 S::*f) {
    return [f](RenderConfig& c, double, const vec3& v, const std::string&) { c.settings.*f = v; return Outcome::success(); };
}
auto camera_field(float render::CameraSettings::*f) {
    return [f](RenderConfig& c, double v, const vec3&, const std::string&) { c.settings.camera.*f = static_cast<float>(v); return Outcome::success(); };
}

const std::vector<RenderKey>& keys() {
    static const std::vector<RenderKey> k = {
        {"display", "width", Kind::integer, 16, 16384, "frame width in pixels (headless frames, initial window)", int_field(&S::width)},
        {"display", "height", Kind::integer, 16, 16384, "frame height in pixels", int_field(&S::height)},
        {"display", "msaa_samples", Kind::integer, 0, 16, "multisample anti-aliasing samples (0/1 off; clamped to the GPU's maximum)", int_field(&S::msaa_samples)},
        {"display", "vsync", Kind::boolean, 0, 1, "window: swap buffers on vertical blank", bool_field(&S::vsync)},
        {"display", "fullscreen", Kind::boolean, 0, 1, "window: start fullscreen", bool_field(&S::fullscreen)},
        {"camera", "distance_m", Kind::number, 0.5, 50, "horizontal distance from the followed point (m)", camera_field(&render::CameraSettings::distance_m)},
        {"camera", "height_m", Kind::number, -10, 50, "camera height above the followed point (m)", camera_field(&render::CameraSettings::height_m)},
        {"camera", "azimuth_deg", Kind::number, -360, 360, "world-fixed direction the camera looks from (°; 0 from −Z)", camera_field(&render::CameraSettings::azimuth_deg)},
        {"camera", "fov_deg", Kind::number, 10, 120, "vertical field of view (°)", camera_field(&render::CameraSettings::fov_deg)},
        {"camera", "smoothing_s", Kind::number, 0, 10, "follow time constant (s); 0 snaps to the puppet", camera_field(&render::CameraSettings::smoothing_s)},
        {"camera", "target_height_m", Kind::number, 0, 3, "followed point above the puppet's root (m)", camera_field(&render::CameraSettings::target_height_m)},
        {"colours", "sky", Kind::colour, 0, 1, "background and fog colour", colour_field(&S::sky_colour)},
        {"colours", "body", Kind::colour, 0, 1, "torso, head and hips", colour_field(&S::body_colour)},
        {"colours", "left", Kind::colour, 0, 1, "left limbs", colour_field(&S::left_colour)},
        {"colours", "right", Kind::colour, 0, 1, "right limbs", colour_field(&S::right_colour)},
        {"colours", "ground", Kind::colour, 0, 1, "ground and heightfield", colour_field(&S::ground_colour)},
        {"colours", "box", Kind::colour, 0, 1, "terrain boxes (steps, platforms)", colour_field(&S::box_colour)},
        {"colours", "slope", Kind::colour, 0, 1, "terrain slopes", colour_field(&S::slope_colour)},
        {"colours", "overlay", Kind::colour, 0, 1, "skeleton lines", colour_field(&S::overlay_colour)},
        {"colours", "hud", Kind::colour, 0, 1, "HUD text", colour_field(&S::hud_colour)},
        {"overlays", "skeleton", Kind::boolean, 0, 1, "skeleton lines shown at start (key 1)", bool_field(&S::show_skeleton)},
        {"overlays", "feet", Kind::boolean, 0, 1, "foot targets and contact markers shown at start (key 2)", bool_field(&S::show_feet)},
        {"overlays", "gait", Kind::boolean, 0, 1, "gait swing splines shown at start (key 3)", bool_field(&S::show_gait)},
        {"overlays", "motion_graph", Kind::boolean, 0, 1, "motion-graph state line shown at start (key 4)", bool_field(&S::show_motion_graph)},
        {"overlays", "hud", Kind::boolean, 0, 1, "text HUD shown at start (key H)", bool_field(&S::show_hud)},
        {"kms", "device", Kind::text, 0, 0, "DRM device node; empty picks the first with a connected display",
         [](RenderConfig& c, double, const vec3&, const std::string& t) { c.drm_device = t; return Outcome::success(); }},
        {"render", "character", Kind::text, 0, 0,
         "skinned glTF 2.0 character (.gltf/.glb) drawn instead of the capsules; empty: the capsules; relative to this file's folder",
         [](RenderConfig& c, double, const vec3&, const std::string& t) { c.character = t; return Outcome::success(); }},
        {"kms", "connector", Kind::text, 0, 0, "connector name such as HDMI-A-1; empty picks the first connected",
         [](RenderConfig& c, double, const vec3&, const std::string& t) { c.kms.connector = t; return Outcome::success(); }},
        {"kms", "mode", Kind::text, 0, 0, "forced mode WIDTHxHEIGHT or WIDTHxHEIGHT@HZ; empty chooses by policy",
         [](RenderConfig& c, double, const vec3&, const std::string& t) {
             c.kms.width = c.kms.height = c.kms.refresh_hz = 0;
             if (t.empty() || parse_mode_text(t, c.kms)) return Outcome::success();
             return Outcome::failure(std::string("expected WIDTHxHEIGHT or WIDTHxHEIGHT@HZ (e.g. 1920x1080@60), got \"") + t + "\"");
         }},
        {"kms", "policy", Kind::text, 0, 0, "mode choice without a forced mode: preferred or highest_refresh",
         [](RenderConfig& c, double, const vec3&, const std::string& t) {
             if (t == "preferred") c.kms.policy = render::KmsModePolicy::preferred;
             else if (t == "highest_refresh") c.kms.policy = render::KmsModePolicy::highest_refresh;
             else return Outcome::failure(std::string("expected \"preferred\" or \"highest_refresh\", got \"") + t + "\"");
             return Outcome::success();
         }},
    };
    return k;
}

int line_of(const toml::node& node) { return static_cast<int>(node.source().begin.line); }

std::string number_text(double v) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
}

// `[character]`: role = "joint name" lines (the roles of retarget/humanoid.hpp).
void read_character_map(const toml::node& table_node, const std::string& file, RenderConfig& config) {
    const toml::table* table = table_node.as_table();
    if (!table) throw ConfigError(file, line_of(table_node), "character", "expected a table ([character])");
    config.character_map.clear();
    config.character_map_lines.clear();
    config.character_origin = file;
    for (const auto& [key, node] : *table) {
        const std::string role(key.str());
        const auto& names = retarget::role_names();
        if (std::find_if(names.begin(), names.end(), [&](const char* n) { return role == n; }) == names.end())
            throw ConfigError(file, line_of(node), "character." + role,
                              "unknown role (expected a puppet joint name: pelvis, spine_01, ..., toe_r; docs/render.md)");
        const auto* v = node.as_string();
        if (!v || v->get().empty())
            throw ConfigError(file, line_of(node), "character." + role, "expected the character's joint name as a non-empty string");
        config.character_map.emplace_back(role, v->get());
        config.character_map_lines.push_back(line_of(node));
    }
}

const char* kind_name(Kind k) {
    switch (k) {
        case Kind::integer: return "integer";
        case Kind::number: return "float";
        case Kind::boolean: return "boolean";
        case Kind::colour: return "colour";
        case Kind::text: return "string";
    }
    return "?";
}
}  // namespace

std::vector<ConfigKeyInfo> render_config_schema() {
    std::vector<ConfigKeyInfo> out;
    for (const RenderKey& k : keys()) out.push_back({k.table, k.key, kind_name(k.kind), k.min, k.max, k.doc});
    return out;
}

bool parse_mode_text(std::string_view t, render::KmsModeRequest& r) {
    int w = 0, h = 0, hz = 0;
    const char* p = t.data();
    const char* end = t.data() + t.size();
    auto a = std::from_chars(p, end, w);
    if (a.ec != std::errc() || a.ptr == end || *a.ptr != 'x') return false;
    auto b = std::from_chars(a.ptr + 1, end, h);
    if (b.ec != std::errc()) return false;
    if (b.ptr != end) {
        if (*b.ptr != '@') return false;
        auto c = std::from_chars(b.ptr + 1, end, hz);
        if (c.ec != std::errc() || c.ptr != end || hz <= 0 || hz > 1000) return false;
    }
    if (w <= 0 || h <= 0 || w > 16384 || h > 16384) return false;
    r.width = w;
    r.height = h;
    r.refresh_hz = hz;
    return true;
}

RenderConfig apply_render_config_text(const RenderConfig& base, std::string_view text, const std::string& file) {
    toml::table doc;
    try {
        doc = toml::parse(text, file);
    } catch (const toml::parse_error& e) {
        throw ConfigError(file, static_cast<int>(e.source().begin.line), "", "TOML syntax error: " + std::string(e.description()));
    }
    RenderConfig config = base;
    for (const auto& [table_key, table_node] : doc) {
        const std::string table_name(table_key.str());
        if (table_name == "character") {
            read_character_map(table_node, file, config);
            continue;
        }
        std::string known;
        for (const RenderKey& k : keys())
            if (table_name == k.table) known += (known.empty() ? "" : ", ") + std::string(k.key);
        if (known.empty())
            throw ConfigError(file, line_of(table_node), table_name,
                              "unknown table (expected display, camera, colours, overlays, kms, render or character)");
        const toml::table* table = table_node.as_table();
        if (!table) throw ConfigError(file, line_of(table_node), table_name, "expected a table ([" + table_name + "])");
        for (const auto& [key, node] : *table) {
            const std::string full = table_name + "." + std::string(key.str());
            const RenderKey* spec = nullptr;
            for (const RenderKey& k : keys())
                if (table_name == k.table && key.str() == k.key) spec = &k;
            if (!spec) throw ConfigError(file, line_of(node), full, "unknown key (expected one of: " + known + ")");
            const std::string range = "[" + number_text(spec->min) + ", " + number_text(spec->max) + "]";
            double number = 0.0;
            vec3 colour{0.0f};
            std::string string_value;
            switch (spec->kind) {
                case Kind::integer: {
                    const auto* v = node.as_integer();
                    if (!v || v->get() < spec->min || v->get() > spec->max)
                        throw ConfigError(file, line_of(node), full, "expected an integer in " + range);
                    number = static_cast<double>(v->get());
                    break;
                }
                case Kind::number: {
                    if (const auto* f = node.as_floating_point()) number = f->get();
                    else if (const auto* i = node.as_integer()) number = static_cast<double>(i->get());
                    else throw ConfigError(file, line_of(node), full, "expected a number in " + range);
                    if (!std::isfinite(number) || number < spec->min || number > spec->max)
                        throw ConfigError(file, line_of(node), full, number_text(number) + " is out of range: expected a number in " + range);
                    break;
                }
                case Kind::boolean: {
                    const auto* v = node.as_boolean();
                    if (!v) throw ConfigError(file, line_of(node), full, "expected true or false");
                    number = v->get() ? 1.0 : 0.0;
                    break;
                }
                case Kind::colour: {
                    const auto* a = node.as_array();
                    if (!a || a->size() != 3)
                        throw ConfigError(file, line_of(node), full, "expected a colour [r, g, b] of three numbers in [0, 1]");
                    for (std::size_t i = 0; i < 3; ++i) {
                        const toml::node& e = *a->get(i);
                        double c = -1.0;
                        if (const auto* f = e.as_floating_point()) c = f->get();
                        else if (const auto* n = e.as_integer()) c = static_cast<double>(n->get());
                        if (!(c >= 0.0 && c <= 1.0))
                            throw ConfigError(file, line_of(node), full, "expected a colour [r, g, b] of three numbers in [0, 1]");
                        colour[static_cast<int>(i)] = static_cast<float>(c);
                    }
                    break;
                }
                case Kind::text: {
                    const auto* v = node.as_string();
                    if (!v) throw ConfigError(file, line_of(node), full, "expected a string");
                    string_value = v->get();
                    break;
                }
            }
            if (const Outcome stored = spec->set(config, number, colour, string_value); !stored.ok())
                throw ConfigError(file, line_of(node), full, stored.problem());
            if (full == "render.character" && !string_value.empty() && string_value.front() != '/') {
                const std::size_t slash = file.find_last_of('/');
                if (slash != std::string::npos) config.character = file.substr(0, slash + 1) + string_value;
            }
        }
    }
    return config;
}

std::string_view default_render_config_text() { return embedded::find("config/render.toml"); }

RenderConfig load_render_config(const std::string& user_file) {
    RenderConfig config = apply_render_config_text(RenderConfig{}, default_render_config_text(), "config/render.toml");
    if (user_file.empty()) return config;
    std::string text;
    try {
        text = read_text_file(user_file);
    } catch (const std::exception&) {
        throw ConfigError(user_file, 0, "", "cannot open the render settings file");
    }
    return apply_render_config_text(config, text, user_file);
}

}  // namespace marionette
