// The parameter panel's layout (tuning_ui.hpp): Save row, message, then one
// collapsing section per table with a slider and a reset button per key.
#include <imgui.h>
#include <imgui_internal.h>  // SetFocusID: the pad starts on the first slider

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string>

#include "app/config/config.hpp"
#include "app/ui/tuning_ui.hpp"

namespace marionette::ui {

namespace {

std::string number_text(float v) {
    char buf[64];
    const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
    (void)ec;
    std::string s(buf, end);
    if (s.find_first_of(".eE") == std::string::npos) s += ".0";
    return s;
}

// Enough decimals that one gamepad step (1 % of the range) shows.
int decimals_for(double min, double max) {
    const double step = (max - min) / 1000.0;
    if (!(step > 0.0)) return 3;
    return std::clamp(static_cast<int>(std::ceil(-std::log10(step))), 1, 6);
}

// Ranges over three decades slide logarithmically (turn rates, seeds, timeouts).
ImGuiSliderFlags slider_flags(const PanelKey& k) {
    ImGuiSliderFlags flags = ImGuiSliderFlags_AlwaysClamp;
    if (k.min > 0.0 && k.max / k.min > 1000.0) flags |= ImGuiSliderFlags_Logarithmic;
    return flags;
}

const char* section_title(const std::string& table) {
    if (table == "gait") return "[gait] the spline-IK walk";
    if (table == "motion") return "[motion] pose source";
    if (table == "motion_graph") return "[motion_graph] graph controller";
    return "input dead zone ([locomotion])";
}

}  // namespace

void TuningUi::draw_row(std::size_t index) {
    const PanelKey& k = keys_[index];
    ImGui::PushID(static_cast<int>(index));
    const std::optional<double> value = config_number(working_, k.table, k.key);
    const std::optional<double> fallback = config_number(defaults_, k.table, k.key);
    if (k.locked) ImGui::BeginDisabled();
    if (k.type == "string") {
        ImGui::Text("%-24s %s", k.key.c_str(), motion_source_name(working_.sim.motion_source).c_str());
    } else if (k.type == "integer") {
        int v = static_cast<int>(value.value_or(0.0));
        // ImGui's integer sliders take ranges within ±2^30; wider ones (seeds) drag.
        const bool wide = k.max > 1.0e9;
        const bool changed = wide ? ImGui::DragInt(k.key.c_str(), &v, 1.0f, static_cast<int>(k.min), static_cast<int>(k.max),
                                                   "%d", ImGuiSliderFlags_AlwaysClamp)
                                  : ImGui::SliderInt(k.key.c_str(), &v, static_cast<int>(k.min), static_cast<int>(k.max),
                                                     "%d", slider_flags(k));
        if (changed) edit(k.table, k.key, std::to_string(v));
    } else {
        float v = static_cast<float>(value.value_or(0.0));
        char format[16];
        std::snprintf(format, sizeof format, "%%.%df", decimals_for(k.min, k.max));
        if (ImGui::SliderFloat(k.key.c_str(), &v, static_cast<float>(k.min), static_cast<float>(k.max), format,
                               slider_flags(k)))
            edit(k.table, k.key, number_text(v));
    }
    if (!k.locked && first_editable_ == index) ImGui::SetItemDefaultFocus();  // where a new window's navigation starts
    if (focus_first_ && index == first_editable_) {
        // Gamepad navigation starts here, highlighted, rather than on nothing
        // (ImGui would wait for a first d-pad press to pick an item).
        ImGui::SetFocusID(ImGui::GetItemID(), ImGui::GetCurrentWindow());
        ImGui::GetCurrentContext()->NavDisableHighlight = false;
        ImGui::GetCurrentContext()->NavDisableMouseHover = true;
        if (++focus_frames_ >= 3) focus_first_ = false;  // past ImGui's own choice for an appearing window
    }
    if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
        ImGui::SetTooltip("%s.%s: %s%s%s", k.table.c_str(), k.key.c_str(), k.doc.c_str(), k.locked ? "\nlocked: " : "",
                          k.why_locked.c_str());
    if (!k.locked && k.type != "string") {
        ImGui::SameLine();
        const bool is_default = value && fallback && *value == *fallback;
        if (is_default) ImGui::BeginDisabled();
        if (ImGui::SmallButton("reset")) reset(k);
        if (is_default) ImGui::EndDisabled();
    } else {
        ImGui::SameLine();
        ImGui::TextDisabled("(locked)");
    }
    if (k.locked) ImGui::EndDisabled();
    ImGui::PopID();
}

void TuningUi::draw_panel(float width, float height) {
    const float margin = 8.0f;
    ImGui::SetNextWindowPos(ImVec2(margin, margin), ImGuiCond_Always);
    // The left part of the screen, so the puppet stays in view on the right.
    const float panel = std::min(width - 2 * margin, std::max(400.0f, std::min(620.0f, width * 0.62f)));
    ImGui::SetNextWindowSize(ImVec2(panel, height - 2 * margin), ImGuiCond_Always);
    ImGui::Begin("tuning  (back+start or F1: close)", nullptr,
                 ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoMove |
                     ImGuiWindowFlags_NoResize);
    if (ImGui::Button("Save")) save(std::string(path_buffer_.data()));
    ImGui::SameLine();
    ImGui::SetNextItemWidth(-1.0f);
    ImGui::InputText("##file", path_buffer_.data(), path_buffer_.size());
    ImGui::TextColored(message_problem_ ? ImVec4(1.0f, 0.45f, 0.4f, 1.0f) : ImVec4(0.6f, 0.9f, 0.6f, 1.0f), "%s",
                       message_.empty() ? "A: adjust  B: back  d-pad: move  Y: save  LB/RB: fine/coarse" : message_.c_str());
    ImGui::Separator();
    ImGui::PushItemWidth(std::max(110.0f, panel * 0.42f));
    std::string table;
    bool open = false;
    bool first_drawn = false;
    for (std::size_t i = 0; i < keys_.size(); ++i) {
        const std::string section = keys_[i].table == "locomotion" ? "input" : keys_[i].table;
        if (section != table) {
            table = section;
            open = ImGui::CollapsingHeader(section_title(keys_[i].table), ImGuiTreeNodeFlags_DefaultOpen);
        }
        if (open) draw_row(i);
        first_drawn = first_drawn || (open && i == first_editable_);
    }
    if (!first_drawn) focus_first_ = false;  // its section is collapsed: ImGui's own choice stands
    ImGui::PopItemWidth();
    draw_terrain_section();
    draw_spline_section(ImGui::GetContentRegionAvail().x);
    ImGui::End();
}

}  // namespace marionette::ui
