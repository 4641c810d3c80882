// The tuning panel's terrain editor (tuning_ui.hpp, docs/ui.md "Terrain
// editor"): rows of step buttons, each press one TerrainAction on the working
// terrain (terrain_edit.hpp does the edit), handed over like a slider's edit.
#include <imgui.h>
#include <imgui_internal.h>  // SetFocusID: west puts the pad on the section's first button

#include <cstdio>
#include <filesystem>
#include <string>

#include "app/config/config.hpp"
#include "app/config/terrain_file.hpp"
#include "app/io/files.hpp"
#include "app/ui/terrain_edit.hpp"
#include "app/ui/toml_edit.hpp"
#include "app/ui/tuning_ui.hpp"

namespace marionette::ui {

namespace {

bool is_builtin_terrain(const std::string& name) {
    for (const char* b : kBuiltinTerrains)
        if (name == b || name == "builtin:" + std::string(b)) return true;
    return false;
}

// The box or slope step (move, resize, tilt, delete) on feature `index`.
bool box_step(Terrain& t, std::size_t i, TerrainAction a) {
    const float m = kTerrainMoveStep, h = kTerrainHeightStep;
    switch (a) {
        case TerrainAction::box_x_minus: return move_box(t, i, -m, 0.0f, 0.0f);
        case TerrainAction::box_x_plus: return move_box(t, i, m, 0.0f, 0.0f);
        case TerrainAction::box_z_minus: return move_box(t, i, 0.0f, -m, 0.0f);
        case TerrainAction::box_z_plus: return move_box(t, i, 0.0f, m, 0.0f);
        case TerrainAction::box_lower: return move_box(t, i, 0.0f, 0.0f, -h);
        case TerrainAction::box_raise: return move_box(t, i, 0.0f, 0.0f, h);
        case TerrainAction::box_narrower: return resize_box(t, i, -m, 0.0f);
        case TerrainAction::box_wider: return resize_box(t, i, m, 0.0f);
        case TerrainAction::box_shorter: return resize_box(t, i, 0.0f, -m);
        case TerrainAction::box_longer: return resize_box(t, i, 0.0f, m);
        case TerrainAction::box_delete: return delete_box(t, i);
        default: return false;
    }
}

bool slope_step(Terrain& t, std::size_t i, TerrainAction a) {
    const float m = kTerrainMoveStep, h = kTerrainHeightStep, g = kTerrainGradeStep;
    switch (a) {
        case TerrainAction::slope_x_minus: return move_slope(t, i, -m, 0.0f, 0.0f);
        case TerrainAction::slope_x_plus: return move_slope(t, i, m, 0.0f, 0.0f);
        case TerrainAction::slope_z_minus: return move_slope(t, i, 0.0f, -m, 0.0f);
        case TerrainAction::slope_z_plus: return move_slope(t, i, 0.0f, m, 0.0f);
        case TerrainAction::slope_lower: return move_slope(t, i, 0.0f, 0.0f, -h);
        case TerrainAction::slope_raise: return move_slope(t, i, 0.0f, 0.0f, h);
        case TerrainAction::slope_tilt_x_minus: return tilt_slope(t, i, -g, 0.0f);
        case TerrainAction::slope_tilt_x_plus: return tilt_slope(t, i, g, 0.0f);
        case TerrainAction::slope_tilt_z_minus: return tilt_slope(t, i, 0.0f, -g);
        case TerrainAction::slope_tilt_z_plus: return tilt_slope(t, i, 0.0f, g);
        case TerrainAction::slope_delete: return delete_slope(t, i);
        default: return false;
    }
}

std::string describe(const Terrain& t) {
    char line[128];
    std::snprintf(line, sizeof line, "%zu box(es), %zu slope(s), heightfield %dx%d", t.boxes.size(), t.slopes.size(),
                  t.heightfield.nx, t.heightfield.nz);
    return line;
}

}  // namespace

bool TuningUi::terrain_action(TerrainAction a) {
    Terrain t = working_.sim.terrain;
    bool changed = false;
    std::string what;
    const int boxes = static_cast<int>(t.boxes.size()), slopes = static_cast<int>(t.slopes.size());
    if (a == TerrainAction::select_next_box || a == TerrainAction::select_next_slope) {
        int& selected = a == TerrainAction::select_next_box ? selected_box_ : selected_slope_;
        const int count = a == TerrainAction::select_next_box ? boxes : slopes;
        selected = count == 0 ? -1 : (selected + 1) % count;
        return count != 0;
    }
    if (a == TerrainAction::add_box) {
        selected_box_ = static_cast<int>(add_box(t, puppet_x_, puppet_z_, 1.0f, 0.1f));
        changed = true;
        what = "added box " + std::to_string(selected_box_) + " under the puppet";
    } else if (a == TerrainAction::add_slope) {
        selected_slope_ = static_cast<int>(add_slope(t, puppet_x_, puppet_z_, 1.0f, 0.05f));
        changed = true;
        what = "added slope " + std::to_string(selected_slope_) + " under the puppet";
    } else if (a == TerrainAction::brush_raise || a == TerrainAction::brush_lower) {
        const float delta = a == TerrainAction::brush_raise ? brush_step : -brush_step;
        const int points = brush_heightfield(t, puppet_x_, puppet_z_, brush_radius, delta);
        changed = points > 0;
        what = "brushed " + std::to_string(points) + " heightfield point(s) under the puppet";
    } else if (a <= TerrainAction::box_delete) {
        if (selected_box_ < 0 || selected_box_ >= boxes) {
            say("terrain: no box selected (add one, or select the next)", true);
            return false;
        }
        changed = box_step(t, static_cast<std::size_t>(selected_box_), a);
        what = "box " + std::to_string(selected_box_) + (a == TerrainAction::box_delete ? " deleted" : " edited");
        if (a == TerrainAction::box_delete) selected_box_ = static_cast<int>(t.boxes.size()) - 1;
    } else {
        if (selected_slope_ < 0 || selected_slope_ >= slopes) {
            say("terrain: no slope selected (add one, or select the next)", true);
            return false;
        }
        changed = slope_step(t, static_cast<std::size_t>(selected_slope_), a);
        what = "slope " + std::to_string(selected_slope_) + (a == TerrainAction::slope_delete ? " deleted" : " edited");
        if (a == TerrainAction::slope_delete) selected_slope_ = static_cast<int>(t.slopes.size()) - 1;
    }
    if (!changed || t == working_.sim.terrain) {
        say("terrain: " + what + ": nothing changed", true);
        return false;
    }
    working_.sim.terrain = std::move(t);
    pending_ = true;
    say("terrain: " + what + " (" + describe(working_.sim.terrain) + ")", false);
    return true;
}

std::string TuningUi::terrain_save_path() const {
    const std::string& name = working_.sim.terrain_name;
    if (name.empty() || name == "inline" || is_builtin_terrain(name)) return "marionette-terrain.toml";
    return name;
}

bool TuningUi::save_terrain(const std::string& path) {
    const std::string problem = save_terrain_file(working_.sim.terrain, path);
    if (!problem.empty()) {
        say("save terrain: " + path + ": " + problem, true);
        return false;
    }
    if (!name_terrain_in_config(path)) return false;
    say("saved the terrain (" + describe(working_.sim.terrain) + ") to " + path + "; [terrain] name = \"" + path +
            "\" in " + std::string(path_buffer_.data()),
        false);
    return true;
}

// `[terrain] name = "PATH"` into the configuration file Save writes (the panel's
// file field), comments kept, so `run --config` starts on the saved terrain;
// checked by loading the result, which must give the working terrain.
bool TuningUi::name_terrain_in_config(const std::string& terrain_path) {
    const std::string config = path_buffer_.data();
    if (config.empty()) {
        say("save terrain: written to " + terrain_path + ", but no configuration file is named to point at it", true);
        return false;
    }
    std::string text = "# marionette configuration, saved by the tuning UI (docs/ui.md)\n";
    std::string quoted = "\"";
    for (char c : terrain_path) quoted += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
    quoted += "\"";
    try {
        if (std::filesystem::exists(config)) text = read_text_file(config);
        text = set_toml_value(text, "terrain", "name", quoted);
        const AppConfig loaded = apply_config_text(default_config(), text, config);
        if (!(loaded.sim.terrain == working_.sim.terrain)) {
            say("save terrain: written to " + terrain_path + "; " + config +
                    " not changed: with [terrain] name pointing at it, it would start on other ground "
                    "(inline [terrain] data in it win over name)",
                true);
            return false;
        }
    } catch (const std::exception& e) {
        say("save terrain: written to " + terrain_path + "; " + config + " not changed: " + e.what(), true);
        return false;
    }
    if (const std::string problem = write_replacing(config, text); !problem.empty()) {
        say("save terrain: written to " + terrain_path + "; " + problem, true);
        return false;
    }
    return true;
}

void TuningUi::terrain_buttons(const char* label, std::initializer_list<std::pair<const char*, TerrainAction>> buttons) {
    ImGui::TextUnformatted(label);
    for (const auto& [text, action] : buttons) {
        ImGui::SameLine();
        ImGui::PushID(static_cast<int>(action));
        if (ImGui::SmallButton(text)) (void)terrain_action(action);
        if (jump_to_terrain_ && action == TerrainAction::add_box) {
            // West: the pad lands on "add box", scrolled into view, held for a few
            // frames past ImGui's own focus handling (as the first slider's is).
            ImGui::SetFocusID(ImGui::GetItemID(), ImGui::GetCurrentWindow());
            ImGui::GetCurrentContext()->NavDisableHighlight = false;
            ImGui::GetCurrentContext()->NavDisableMouseHover = true;
            ImGui::SetScrollHereY(0.2f);
            if (++jump_frames_ >= 3) jump_to_terrain_ = false;
        }
        ImGui::PopID();
    }
}

void TuningUi::draw_terrain_section() {
    // Collapsed at first: the pad reaches it below the sliders, or at once with west.
    if (jump_to_terrain_) ImGui::SetNextItemOpen(true);
    if (!ImGui::CollapsingHeader("[terrain] editor")) return;
    const Terrain& t = working_.sim.terrain;
    ImGui::Text("%s; the puppet at x %.2f z %.2f", describe(t).c_str(), static_cast<double>(puppet_x_),
                static_cast<double>(puppet_z_));
    using A = TerrainAction;
    terrain_buttons("add under the puppet:", {{"box", A::add_box}, {"slope", A::add_slope}});
    if (selected_box_ >= static_cast<int>(t.boxes.size())) selected_box_ = static_cast<int>(t.boxes.size()) - 1;
    if (selected_slope_ >= static_cast<int>(t.slopes.size())) selected_slope_ = static_cast<int>(t.slopes.size()) - 1;
    ImGui::Text("box %d of %zu", selected_box_, t.boxes.size());
    terrain_buttons("  box:", {{"next", A::select_next_box}, {"x-", A::box_x_minus}, {"x+", A::box_x_plus},
                               {"z-", A::box_z_minus}, {"z+", A::box_z_plus}, {"lower", A::box_lower},
                               {"raise", A::box_raise}, {"delete", A::box_delete}});
    terrain_buttons("  box size:", {{"x-", A::box_narrower}, {"x+", A::box_wider}, {"z-", A::box_shorter},
                                    {"z+", A::box_longer}});
    ImGui::Text("slope %d of %zu", selected_slope_, t.slopes.size());
    terrain_buttons("  slope:", {{"next", A::select_next_slope}, {"x-", A::slope_x_minus}, {"x+", A::slope_x_plus},
                                 {"z-", A::slope_z_minus}, {"z+", A::slope_z_plus}, {"lower", A::slope_lower},
                                 {"raise", A::slope_raise}, {"delete", A::slope_delete}});
    terrain_buttons("  slope grade:", {{"x-", A::slope_tilt_x_minus}, {"x+", A::slope_tilt_x_plus},
                                       {"z-", A::slope_tilt_z_minus}, {"z+", A::slope_tilt_z_plus}});
    ImGui::SliderFloat("brush radius (m)", &brush_radius, 0.1f, 3.0f, "%.2f", ImGuiSliderFlags_AlwaysClamp);
    ImGui::SliderFloat("brush step (m)", &brush_step, 0.01f, 0.2f, "%.2f", ImGuiSliderFlags_AlwaysClamp);
    terrain_buttons("heightfield:", {{"raise", A::brush_raise}, {"lower", A::brush_lower}});
    const std::string path = terrain_save_path();
    if (ImGui::Button("Save terrain")) (void)save_terrain(path);
    ImGui::SameLine();
    ImGui::TextDisabled("to %s", path.c_str());
}

}  // namespace marionette::ui
