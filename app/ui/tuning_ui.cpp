#include "app/ui/tuning_ui.hpp"

#include <SDL2/SDL.h>
#include <imgui.h>
#include <backends/imgui_impl_sdl.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "app/config/config.hpp"
#include "app/io/files.hpp"
#include "app/ui/toml_edit.hpp"
#include "render_es/imgui_gles3.hpp"

namespace marionette::ui {

std::vector<PanelKey> panel_keys() {
    std::vector<PanelKey> out;
    for (const ConfigKeyInfo& k : config_schema()) {
        const bool wanted = k.table == "gait" || k.table == "motion" || k.table == "motion_graph" ||
                            (k.table == "locomotion" && k.key == "stick_deadzone");
        if (!wanted) continue;
        PanelKey p{k.table, k.key, k.type, k.min, k.max, k.doc, false, ""};
        if (k.type == "string") {
            p.locked = true;
            p.why_locked = "needs a restart when the graph's skeleton differs; edit the file";
        } else if (!k.live) {
            p.locked = true;
            p.why_locked = "read by graph builds only, never by the running simulation";
        }
        out.push_back(std::move(p));
    }
    // The walk first (what a person tunes most), then the pose source, the
    // graph controller and the dead zone; schema order within each.
    auto rank = [](const PanelKey& k) {
        return k.table == "gait" ? 0 : k.table == "motion" ? 1 : k.table == "motion_graph" ? 2 : 3;
    };
    std::stable_sort(out.begin(), out.end(), [&](const PanelKey& a, const PanelKey& b) { return rank(a) < rank(b); });
    return out;
}

TuningUi::TuningUi(render::Platform& platform, TuningUiOptions options)
    : platform_(platform), options_(std::move(options)), defaults_(default_config()), working_(options_.base),
      keys_(panel_keys()) {
    save_path_ = !options_.save_file.empty() ? options_.save_file
                 : !options_.source_file.empty() ? options_.source_file : "marionette-tuned.toml";
    std::snprintf(path_buffer_.data(), path_buffer_.size(), "%s", save_path_.c_str());
    while (first_editable_ + 1 < keys_.size() && keys_[first_editable_].locked) ++first_editable_;
    IMGUI_CHECKVERSION();
    context_ = ImGui::CreateContext();
    ImGui::SetCurrentContext(context_);
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr;  // no imgui.ini: the layout is fixed, nothing is written behind the user's back
    io.LogFilename = nullptr;
    io.ConfigFlags |= ImGuiConfigFlags_NavEnableGamepad;
    io.BackendFlags |= ImGuiBackendFlags_HasGamepad;
    ImGui::StyleColorsDark();
    ImGui::GetStyle().Colors[ImGuiCol_WindowBg].w = 0.88f;
    if (platform_.native_window() != nullptr) {
        sdl_ = ImGui_ImplSDL2_InitForOpenGL(static_cast<SDL_Window*>(platform_.native_window()),
                                            platform_.native_context());
    }
    // Keyboard navigation needs the SDL backend's key map (ImGui asserts without
    // one): in a window only; on KMS and headless the pad alone navigates.
    if (sdl_) io.ConfigFlags |= ImGuiConfigFlags_NavEnableKeyboard;
    renderer_ = std::make_unique<render::ImGuiGles3Renderer>();
}

TuningUi::~TuningUi() {
    ImGui::SetCurrentContext(context_);
    renderer_.reset();
    if (sdl_) ImGui_ImplSDL2_Shutdown();
    ImGui::DestroyContext(context_);
}

void TuningUi::say(const std::string& line, bool problem) {
    message_ = line;
    message_problem_ = problem;
    std::fprintf(options_.out, "ui: %s\n", line.c_str());
    std::fflush(options_.out);
}

void TuningUi::set_open(bool open) {
    if (open == open_) return;
    open_ = open;
    stepper_ = PadStepper{};  // a d-pad held across the chord does not repeat into the panel
    spline_pad_ = false;
    steps_ = 0;
    focus_first_ = open;
    focus_frames_ = 0;
    std::fprintf(options_.out, "ui: %s\n", open ? "opened (the pad drives the panel; the puppet idles)" : "closed");
    std::fflush(options_.out);
}

void TuningUi::feed_pad(const TickInput& held, std::uint64_t held_tick, std::int64_t tick_ns, PadPress press,
                        bool caught_up) {
    pad_ = held;
    press_ = press.event;
    if (press.event & kChordMade) {
        press_ = 0;  // the chord is ours: ImGui does not see back and start
        set_open(!open_);
        return;
    }
    // While the first focus settles (releasing()) no step is shown: ImGui would
    // move the focus back to the first slider after it (seen with 1-5 frames/s).
    steps_ = open_ && !focus_first_ ? stepper_.frame(press, held.buttons, held_tick, tick_ns, caught_up) : 0;
    if (focus_first_) press_ = 0;
}

void TuningUi::adopt(const SimConfig& accepted) { working_.sim = accepted; }

bool TuningUi::take_edit(AppConfig& out) {
    if (!pending_) return false;
    pending_ = false;
    out = working_;
    return true;
}

bool TuningUi::edit(std::string_view table, std::string_view key, const std::string& value_text) {
    const std::string full = std::string(table) + "." + std::string(key);
    const std::optional<std::string> before = config_value_text(working_, table, key);
    if (before && *before == value_text) return true;
    AppConfig next;
    try {
        next = apply_config_text(working_, "[" + std::string(table) + "]\n" + std::string(key) + " = " + value_text + "\n",
                                 "tuning UI");
    } catch (const std::exception& e) {
        say(e.what(), true);
        return false;
    }
    working_ = next;
    pending_ = true;
    if (std::find(edited_.begin(), edited_.end(), full) == edited_.end()) edited_.push_back(full);
    say(full + " " + before.value_or("?") + " -> " + value_text, false);
    return true;
}

bool TuningUi::reset(const PanelKey& key) {
    const std::optional<std::string> value = config_value_text(defaults_, key.table, key.key);
    return value && edit(key.table, key.key, *value);
}

std::optional<std::string> TuningUi::edited_value_text(const std::string& table, const std::string& key) const {
    for (SplineGait g : {SplineGait::walk, SplineGait::run})
        for (SplinePath p : {SplinePath::swing_foot, SplinePath::pelvis, SplinePath::hand})
            if (table == gait_table(g) && key == path_key(p)) return prototype_toml(prototype_of(working_.sim, g, p));
    return config_value_text(working_, table, key);
}

bool TuningUi::save(const std::string& path) {
    if (path.empty()) {
        say("save: no file name", true);
        return false;
    }
    const bool exists = std::filesystem::exists(path);
    std::string text = "# marionette configuration, saved by the tuning UI (docs/ui.md)\n";
    try {
        if (exists) text = read_text_file(path);
    } catch (const std::exception& e) {
        say("save: not written: " + std::string(e.what()), true);  // names the file and why it cannot be read
        return false;
    }
    for (const std::string& full : edited_) {
        const std::size_t dot = full.rfind('.');
        const std::string table = full.substr(0, dot);
        const std::string key = full.substr(dot + 1);
        const std::optional<std::string> value = edited_value_text(table, key);
        if (value) text = set_toml_value(text, table, key, *value);
    }
    try {
        (void)apply_config_text(default_config(), text, path);  // what `run --config` will read
    } catch (const std::exception& e) {
        say("save: not written, the result would not load: " + std::string(e.what()), true);
        return false;
    }
    if (const std::string problem = write_replacing(path, text); !problem.empty()) {
        say("save: " + problem, true);
        return false;
    }
    save_path_ = path;
    say("saved " + std::to_string(edited_.size()) + " edited key(s) to " + path + (exists ? "" : " (new file)"), false);
    return true;
}

void TuningUi::recreate() {
    ImGui::SetCurrentContext(context_);
    renderer_->recreate();
}

bool TuningUi::on_native_event(const void* native) {
    const SDL_Event& e = *static_cast<const SDL_Event*>(native);
    if (e.type == SDL_KEYDOWN && e.key.repeat == 0 && e.key.keysym.sym == SDLK_F1) {
        set_open(!open_);
        return true;
    }
    if (!open_) return false;
    if (e.type == SDL_KEYDOWN && e.key.keysym.sym == SDLK_ESCAPE) {
        set_open(false);  // Esc closes the panel first; the next one closes the window
        return true;
    }
    ImGui::SetCurrentContext(context_);
    if (sdl_) ImGui_ImplSDL2_ProcessEvent(&e);
    const ImGuiIO& io = ImGui::GetIO();
    switch (e.type) {
        case SDL_KEYDOWN:
        case SDL_KEYUP:
        case SDL_TEXTINPUT: return io.WantCaptureKeyboard;
        case SDL_MOUSEMOTION:
        case SDL_MOUSEBUTTONDOWN:
        case SDL_MOUSEBUTTONUP:
        case SDL_MOUSEWHEEL: return io.WantCaptureMouse;
        default: return false;
    }
}

// The pad into ImGui's navigation inputs. The d-pad, south and east are steps
// (PadStepper): down in one frame, up in the next, so ImGui sees each as a fresh
// press (one step) and never runs its own repeat, which it times by summing
// frame times (a stalled frame would turn a tap into a repeat). The fine/coarse
// modifiers and the stick are held values.
void TuningUi::feed_navigation() {
    ImGuiIO& io = ImGui::GetIO();
    if (spline_pad_) spline_pad_steps();  // takes the d-pad, south and east from ImGui
    auto down = [&](Button b) { return (steps_ & button_bit(b)) != 0 ? 1.0f : 0.0f; };
    auto held = [&](Button b) { return (pad_.buttons & button_bit(b)) != 0 ? 1.0f : 0.0f; };
    io.NavInputs[ImGuiNavInput_Activate] = down(Button::south);
    io.NavInputs[ImGuiNavInput_Cancel] = down(Button::east);
    io.NavInputs[ImGuiNavInput_DpadUp] = down(Button::dpad_up);
    io.NavInputs[ImGuiNavInput_DpadDown] = down(Button::dpad_down);
    io.NavInputs[ImGuiNavInput_DpadLeft] = down(Button::dpad_left);
    io.NavInputs[ImGuiNavInput_DpadRight] = down(Button::dpad_right);
    io.NavInputs[ImGuiNavInput_TweakSlow] =
        std::max(held(Button::left_shoulder), static_cast<float>(pad_.left_trigger) / kTriggerScale);
    io.NavInputs[ImGuiNavInput_TweakFast] =
        std::max(held(Button::right_shoulder), static_cast<float>(pad_.right_trigger) / kTriggerScale);
    // In the spline editor's d-pad mode the left stick walks the puppet, it does not scroll.
    const float lx = spline_pad_ ? 0.0f : static_cast<float>(pad_.left_x) / kStickScale;
    const float ly = spline_pad_ ? 0.0f : static_cast<float>(pad_.left_y) / kStickScale;
    io.NavInputs[ImGuiNavInput_LStickLeft] = std::max(0.0f, -lx);
    io.NavInputs[ImGuiNavInput_LStickRight] = std::max(0.0f, lx);
    io.NavInputs[ImGuiNavInput_LStickUp] = std::max(0.0f, ly);
    io.NavInputs[ImGuiNavInput_LStickDown] = std::max(0.0f, -ly);
    // North saves (our shortcut; ImGui's own use of it, text input, is not needed here).
    if (press_ & button_bit(Button::north)) save(std::string(path_buffer_.data()));
    // West jumps to the terrain editor (opened, its first button focused): far
    // below the sliders otherwise; pressed again, to the spline editor's curve.
    if (press_ & button_bit(Button::west)) {
        (next_jump_spline_ ? jump_to_spline_ : jump_to_terrain_) = true;
        next_jump_spline_ = !next_jump_spline_;
        jump_frames_ = 0;
    }
}

void TuningUi::draw(std::int32_t width, std::int32_t height, float dt_s) {
    if (!open_) return;
    ImGui::SetCurrentContext(context_);
    ImGuiIO& io = ImGui::GetIO();
    if (sdl_) {
        // The SDL backend would open and read SDL game controller 0 itself (from
        // this thread, beside the input thread's backend); the pad reaches ImGui
        // from the simulation's input instead (feed_navigation), on KMS too.
        io.ConfigFlags &= ~ImGuiConfigFlags_NavEnableGamepad;
        ImGui_ImplSDL2_NewFrame();
        io.ConfigFlags |= ImGuiConfigFlags_NavEnableGamepad;
    }
    io.DisplaySize = ImVec2(static_cast<float>(width), static_cast<float>(height));
    io.DisplayFramebufferScale = ImVec2(1.0f, 1.0f);
    // The real frame time (ImGui needs it positive). Pad navigation does not
    // depend on it: steps are press edges (feed_navigation).
    io.DeltaTime = std::max(dt_s, 1e-4f);
    feed_navigation();
    ImGui::NewFrame();
    draw_panel(static_cast<float>(width), static_cast<float>(height));
    ImGui::Render();
    renderer_->draw(*ImGui::GetDrawData(), width, height);
}

}  // namespace marionette::ui
