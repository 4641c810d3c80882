// The tuning panel's spline editor (tuning_ui.hpp, docs/ui.md "Spline editor"):
// the walk and run prototypes drawn as curves over phase with their keys and
// tangents (ImGui's draw list), a key dragged with the mouse or stepped with the
// pad, each change handed over like a slider's edit (spline_edit.hpp clamps it).
#include <imgui.h>
#include <imgui_internal.h>  // SetFocusID: west puts the pad on the curve

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include "app/config/config.hpp"
#include "app/ui/tuning_ui.hpp"
#include "runtime/gait/gait.hpp"
#include "runtime/math/hermite_spline.hpp"

namespace marionette::ui {

namespace {

float channel_value(const vec3& v, int channel) { return channel == 0 ? v.x : channel == 1 ? v.y : v.z; }
float key_value(const PrototypeKey& k, int channel) { return channel == 0 ? k.x : channel == 1 ? k.y : k.z; }

const char* channel_meaning(SplinePath path, int channel) {
    static const char* const names[3][3] = {{"x: sideways (m)", "y: lift (m)", "z: step fraction"},
                                            {"x: sway (m)", "y: bob (m)", "z: surge (m)"},
                                            {"x: out (m)", "y: up (m)", "z: forward (m)"}};
    return names[static_cast<int>(path)][channel];
}

// The value range the curve is drawn over: the keys' and the curve's, and 0,
// padded by a quarter, at least 0.05 tall.
void value_range(const std::array<HermiteKey, kMaxPrototypeKeys>& keys, int n, int channel, float& lo, float& hi) {
    lo = 0.0f;
    hi = 0.0f;
    for (int i = 0; i <= 64; ++i) {
        const float v = channel_value(
            sample_hermite(std::span<const HermiteKey>(keys.data(), static_cast<std::size_t>(n)), static_cast<float>(i) / 64.0f)
                .position,
            channel);
        lo = std::min(lo, v);
        hi = std::max(hi, v);
    }
    const float pad = std::max(0.05f - (hi - lo), 0.0f) * 0.5f + (hi - lo) * 0.25f;
    lo -= pad;
    hi += pad;
}

}  // namespace

bool TuningUi::edit_prototype(const SplinePrototype& next) {
    const std::string table = gait_table(spline.gait), key = path_key(spline.path);
    const std::string full = table + "." + key;
    if (const std::string problem = validate_prototype(next, spline.path); !problem.empty()) {
        say(full + ": " + problem, true);  // cannot happen: spline_edit.hpp clamps; kept as the last guard
        return false;
    }
    AppConfig candidate;
    try {
        candidate = apply_config_text(working_, "[" + table + "]\n" + key + " = " + prototype_toml(next) + "\n", "tuning UI");
    } catch (const std::exception& e) {
        say(e.what(), true);
        return false;
    }
    working_ = candidate;
    pending_ = true;
    if (std::find(edited_.begin(), edited_.end(), full) == edited_.end()) edited_.push_back(full);
    const PrototypeKey& k = next.keys[static_cast<std::size_t>(spline.key)];
    char line[160];
    std::snprintf(line, sizeof line, "%s key %d -> [%g, %g, %g, %g]", full.c_str(), spline.key,
                  static_cast<double>(k.phase), static_cast<double>(k.x), static_cast<double>(k.y), static_cast<double>(k.z));
    say(line, false);
    return true;
}

bool TuningUi::spline_move(float dphase, float dvalue) {
    SplinePrototype p = prototype_of(working_.sim, spline.gait, spline.path);
    if (!move_key(p, spline.path, spline.key, dphase, spline.channel, dvalue)) {
        say(std::string(gait_table(spline.gait)) + "." + path_key(spline.path) + " key " + std::to_string(spline.key) +
                ": at its limit (nothing changed)",
            true);
        return false;
    }
    return edit_prototype(p);
}

bool TuningUi::spline_set(float phase, float value) {
    SplinePrototype p = prototype_of(working_.sim, spline.gait, spline.path);
    if (!set_key(p, spline.path, spline.key, phase, spline.channel, value)) return false;
    return edit_prototype(p);
}

void TuningUi::spline_select_next() {
    const int n = prototype_of(working_.sim, spline.gait, spline.path).count;
    spline.key = n > 0 ? (spline.key + 1) % n : 0;
}

void TuningUi::set_spline_pad_mode(bool on) {
    spline_pad_ = on;
    say(on ? "spline: the d-pad moves the key (left/right phase, up/down value), A: next key, B: done"
           : "spline: the d-pad navigates again",
        false);
}

// In pad mode the step buttons edit the curve and ImGui does not see them.
void TuningUi::spline_pad_steps() {
    const std::uint32_t taken = button_bit(Button::dpad_left) | button_bit(Button::dpad_right) |
                                button_bit(Button::dpad_up) | button_bit(Button::dpad_down) |
                                button_bit(Button::south) | button_bit(Button::east);
    const std::uint32_t s = steps_;
    steps_ &= ~taken;
    if ((s & taken) == 0) return;
    const bool fine = (pad_.buttons & button_bit(Button::left_shoulder)) != 0 || pad_.left_trigger > kTriggerScale / 2;
    const bool coarse = (pad_.buttons & button_bit(Button::right_shoulder)) != 0 || pad_.right_trigger > kTriggerScale / 2;
    const float scale = fine ? 0.1f : coarse ? 10.0f : 1.0f;
    const float dp = kSplinePhaseStep * scale, dv = kSplineValueStep * scale;
    if (s & button_bit(Button::dpad_left)) (void)spline_move(-dp, 0.0f);
    if (s & button_bit(Button::dpad_right)) (void)spline_move(dp, 0.0f);
    if (s & button_bit(Button::dpad_up)) (void)spline_move(0.0f, dv);
    if (s & button_bit(Button::dpad_down)) (void)spline_move(0.0f, -dv);
    if (s & button_bit(Button::south)) spline_select_next();
    if (s & button_bit(Button::east)) set_spline_pad_mode(false);
}

void TuningUi::draw_spline_canvas(float width) {
    const SplinePrototype& p = prototype_of(working_.sim, spline.gait, spline.path);
    std::array<HermiteKey, kMaxPrototypeKeys> keys{};
    const int n = build_prototype_keys(p, path_loops(spline.path), keys);
    spline.key = std::clamp(spline.key, 0, std::max(n - 1, 0));
    float lo = 0.0f, hi = 0.0f;
    value_range(keys, n, spline.channel, lo, hi);
    if (spline_drag_ >= 0) lo = drag_lo_, hi = drag_hi_;  // the scale holds still under the mouse
    const ImVec2 size(std::max(width, 100.0f), 150.0f);
    const ImVec2 o = ImGui::GetCursorScreenPos();
    const bool clicked = ImGui::InvisibleButton("curve", size);
    if (jump_to_spline_) {
        ImGui::SetFocusID(ImGui::GetItemID(), ImGui::GetCurrentWindow());
        ImGui::GetCurrentContext()->NavDisableHighlight = false;
        ImGui::GetCurrentContext()->NavDisableMouseHover = true;
        ImGui::SetScrollHereY(0.3f);
        if (++jump_frames_ >= 3) jump_to_spline_ = false;
    }
    auto to_screen = [&](float phase, float v) {
        return ImVec2(o.x + phase * size.x, o.y + (hi - v) / (hi - lo) * size.y);
    };
    const ImGuiIO& io = ImGui::GetIO();
    if (ImGui::IsItemActivated() && io.MouseDown[0]) {
        int nearest = -1;
        float best = 12.0f * 12.0f;  // px²: a key within 12 px is picked
        for (int i = 0; i < n; ++i) {
            const ImVec2 s = to_screen(keys[static_cast<std::size_t>(i)].time,
                                       key_value(p.keys[static_cast<std::size_t>(i)], spline.channel));
            const float d = (s.x - io.MousePos.x) * (s.x - io.MousePos.x) + (s.y - io.MousePos.y) * (s.y - io.MousePos.y);
            if (d < best) best = d, nearest = i;
        }
        spline_drag_ = nearest;
        drag_lo_ = lo, drag_hi_ = hi;
        if (nearest >= 0) spline.key = nearest;
    } else if (clicked && !io.MouseReleased[0]) {
        set_spline_pad_mode(!spline_pad_);  // south on the focused curve
    }
    if (spline_drag_ >= 0 && ImGui::IsItemActive() && io.MouseDelta.x * io.MouseDelta.x + io.MouseDelta.y * io.MouseDelta.y > 0.0f)
        (void)spline_set((io.MousePos.x - o.x) / size.x, hi - (io.MousePos.y - o.y) / size.y * (hi - lo));
    if (!ImGui::IsItemActive()) spline_drag_ = -1;

    ImDrawList* dl = ImGui::GetWindowDrawList();
    dl->PushClipRect(o, ImVec2(o.x + size.x, o.y + size.y), true);  // the faint channels may leave the scale
    dl->AddRectFilled(o, ImVec2(o.x + size.x, o.y + size.y), IM_COL32(20, 24, 30, 230));
    dl->AddRect(o, ImVec2(o.x + size.x, o.y + size.y),
                spline_pad_ ? IM_COL32(255, 200, 60, 255) : IM_COL32(90, 100, 120, 255));
    dl->AddLine(to_screen(0.0f, 0.0f), to_screen(1.0f, 0.0f), IM_COL32(80, 80, 90, 255));  // value 0
    const std::span<const HermiteKey> span(keys.data(), static_cast<std::size_t>(n));
    for (int c = 0; c < 3; ++c) {  // the other channels faint, the selected one bright
        std::array<ImVec2, 97> pts{};
        for (std::size_t i = 0; i < pts.size(); ++i) {
            const float t = static_cast<float>(i) / static_cast<float>(pts.size() - 1);
            pts[i] = to_screen(t, channel_value(sample_hermite(span, t).position, c));
        }
        const ImU32 colour = c == spline.channel ? IM_COL32(120, 200, 255, 255) : IM_COL32(120, 130, 150, 90);
        dl->AddPolyline(pts.data(), static_cast<int>(pts.size()), colour, 0, c == spline.channel ? 2.0f : 1.0f);
    }
    for (int i = 0; i < n; ++i) {
        const HermiteKey& k = keys[static_cast<std::size_t>(i)];
        const float v = channel_value(k.position, spline.channel), slope = channel_value(k.tangent, spline.channel);
        const float h = 0.06f;  // phase each side the tangent handle reaches
        dl->AddLine(to_screen(k.time - h, v - slope * h), to_screen(k.time + h, v + slope * h), IM_COL32(230, 150, 80, 200));
        const bool fixed = !values_editable(p, spline.path, i);
        dl->AddCircleFilled(to_screen(k.time, v), i == spline.key ? 6.0f : 4.0f,
                            i == spline.key ? IM_COL32(255, 220, 80, 255)
                            : fixed         ? IM_COL32(140, 140, 140, 255)
                                            : IM_COL32(240, 240, 240, 255));
    }
    dl->PopClipRect();
}

void TuningUi::draw_spline_section(float width) {
    if (jump_to_spline_) ImGui::SetNextItemOpen(true);
    if (!ImGui::CollapsingHeader("[gait.walk] / [gait.run] spline editor")) {
        if (spline_pad_) set_spline_pad_mode(false);  // collapsed (the mouse): the d-pad navigates again
        return;
    }
    int gait = static_cast<int>(spline.gait), path = static_cast<int>(spline.path);
    ImGui::RadioButton("walk", &gait, 0);
    ImGui::SameLine();
    ImGui::RadioButton("run", &gait, 1);
    ImGui::SameLine(0.0f, 24.0f);
    ImGui::RadioButton("swing foot", &path, 0);
    ImGui::SameLine();
    ImGui::RadioButton("pelvis", &path, 1);
    ImGui::SameLine();
    ImGui::RadioButton("hands", &path, 2);
    if (gait != static_cast<int>(spline.gait) || path != static_cast<int>(spline.path)) {
        spline.gait = static_cast<SplineGait>(gait);
        spline.path = static_cast<SplinePath>(path);
        spline.key = spline.path == SplinePath::swing_foot ? 1 : 0;
    }
    for (int c = 0; c < 3; ++c) {
        if (c) ImGui::SameLine();
        ImGui::RadioButton(channel_meaning(spline.path, c), &spline.channel, c);
    }
    draw_spline_canvas(width);
    const SplinePrototype& p = prototype_of(working_.sim, spline.gait, spline.path);
    const PrototypeKey& k = p.keys[static_cast<std::size_t>(spline.key)];
    ImGui::Text("key %d/%d  phase %.3f  x %.4f  y %.4f  z %.4f", spline.key, p.count, static_cast<double>(k.phase),
                static_cast<double>(k.x), static_cast<double>(k.y), static_cast<double>(k.z));
    ImGui::TextDisabled(spline_pad_ ? "d-pad: move  A: next key  B: done  LB/RB: fine/coarse"
                                    : "drag a key, or A on the curve: the d-pad steps it");
}

}  // namespace marionette::ui
