#pragma once
// The in-app tuning UI (docs/ui.md): a Dear ImGui panel drawn over the puppet
// by the render thread only, opened by the pad chord back + start or F1, and
// navigable with the pad (ImGui gamepad navigation fed from the simulation's
// newest input, so it works on KMS where there is no SDL), the keyboard and the
// mouse (the SDL window, through the packaged SDL2 backend).
//
// It never touches the simulation. An edit is applied to a working copy of the
// configuration with the same schema and checks as a file (apply_config_text);
// the copy is then handed to the writer thread, which offers it to the
// simulation exactly as the file watcher offers a live edit: applied at a tick
// boundary, written into the input log as a configuration change, so `replay`
// reproduces the session. Save writes the edited keys back into the TOML file
// they came from (toml_edit.hpp keeps its comments and key order), or a new one.
#include <array>
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <utility>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "app/config/app_config.hpp"
#include "app/ui/pad_presses.hpp"
#include "app/ui/spline_edit.hpp"
#include "render_es/platform.hpp"
#include "render_es/view.hpp"
#include "runtime/sim/tick_input.hpp"

struct ImGuiContext;

namespace marionette::render {
class ImGuiGles3Renderer;
}

namespace marionette::ui {

struct TuningUiOptions {
    AppConfig base;           // the run's configuration: defaults, then source_file
    std::string source_file;  // where it came from ("" = the defaults only)
    std::string save_file;    // where Save writes ("" = source_file, else marionette-tuned.toml)
    std::FILE* out = stderr;  // one line per edit, save and refusal
};

// One row of the parameter panel: a documented key with its range.
struct PanelKey {
    std::string table;
    std::string key;
    std::string type;        // "integer", "float" or "string"
    double min = 0.0;
    double max = 0.0;
    std::string doc;
    bool locked = false;     // shown, not editable: read at start or by graph builds only
    std::string why_locked;
};
// The panel's keys: every documented key of [gait], [motion], [motion_graph]
// and the stick dead zone ([locomotion] stick_deadzone), in that order of
// tables and in schema order within each.
std::vector<PanelKey> panel_keys();

// One step of the terrain editor (docs/ui.md, "Terrain editor"), as a pad press
// on one of its buttons makes it: features are added under the puppet, the
// selected box or slope moves, grows, tilts or goes, the brush raises or lowers
// the heightfield under the puppet.
enum class TerrainAction {
    add_box, add_slope, select_next_box, select_next_slope,
    box_x_minus, box_x_plus, box_z_minus, box_z_plus, box_lower, box_raise,
    box_narrower, box_wider, box_shorter, box_longer, box_delete,
    slope_x_minus, slope_x_plus, slope_z_minus, slope_z_plus, slope_lower, slope_raise,
    slope_tilt_x_minus, slope_tilt_x_plus, slope_tilt_z_minus, slope_tilt_z_plus, slope_delete,
    brush_raise, brush_lower,
};
inline constexpr float kTerrainMoveStep = 0.1f;   // m per press: moves and resizes
inline constexpr float kTerrainHeightStep = 0.02f;  // m per press: box tops, slope bases
inline constexpr float kTerrainGradeStep = 0.05f;   // rise/run per press

class TuningUi final : public render::ViewLayer, public render::NativeEventHook {
public:
    // On the render thread, with the platform's context current.
    TuningUi(render::Platform& platform, TuningUiOptions options);
    ~TuningUi() override;
    TuningUi(const TuningUi&) = delete;
    TuningUi& operator=(const TuningUi&) = delete;

    // Before each frame: the newest tick's buttons and sticks (as the pad held
    // them, before the UI took them from the puppet), that tick's number and a
    // tick's length, one press event (ui::press_event and its tick; event 0:
    // none) and whether the press queue is now empty (held d-pad buttons repeat
    // only then, so a queued press is never overtaken). Each press is one step
    // (ui::PadStepper), however long or short the frames are.
    void feed_pad(const TickInput& held, std::uint64_t held_tick, std::int64_t tick_ns, PadPress press,
                  bool caught_up);
    // This frame takes no press event: the last frame showed a step and this one
    // shows it released, or the panel, just opened, is still putting the focus on
    // its first slider (a step taken then would be undone by it), or west just
    // moved it to the terrain editor.
    bool releasing() const { return stepper_.releasing() || focus_first_ || jump_to_terrain_ || jump_to_spline_; }
    bool is_open() const { return open_; }
    void set_open(bool open);
    // A configuration the writer thread has accepted (a file edit, or ours).
    void adopt(const SimConfig& accepted);
    // An edit waiting to be handed over; true once per edit.
    bool take_edit(AppConfig& out);
    const AppConfig& working() const { return working_; }
    const std::string& save_path() const { return save_path_; }
    const std::string& message() const { return message_; }

    // What a slider or a reset button does: sets table.key to the value's TOML
    // text. False (message() says why) when the schema or a relation refuses it.
    bool edit(std::string_view table, std::string_view key, const std::string& value_text);
    bool reset(const PanelKey& key);
    // Writes the edited keys into `path` (made when missing). False, with the
    // reason in message(), when it cannot.
    bool save(const std::string& path);

    // The terrain editor. The puppet's ground position (the newest state's
    // root) is where new features and the brush go.
    void set_puppet_position(float x, float z) {
        puppet_x_ = x;
        puppet_z_ = z;
    }
    // One editor step on the working terrain; handed over like a slider's edit,
    // so the simulation walks on the result from a tick boundary and the log
    // records it. False (message() says why) when it changes nothing.
    bool terrain_action(TerrainAction action);
    int selected_box() const { return selected_box_; }
    int selected_slope() const { return selected_slope_; }
    float brush_radius = 0.5f;  // m
    float brush_step = 0.05f;   // m per press
    // Writes the working terrain as a terrain file (save_terrain_file) to
    // `path`; terrain_save_path() is the terrain's own file, or
    // marionette-terrain.toml for a built-in or inline one.
    bool save_terrain(const std::string& path);
    std::string terrain_save_path() const;

    // The spline editor (docs/ui.md, "Spline editor"): the selected prototype,
    // key and channel (0 x, 1 y, 2 z); key 0 of the swing cannot move, so 1.
    struct SplineSelection {
        SplineGait gait = SplineGait::walk;
        SplinePath path = SplinePath::swing_foot;
        int key = 1;
        int channel = 1;
    };
    SplineSelection spline;
    // Moves the selected key by a phase and a value step (clamped, spline_edit.hpp)
    // or to an absolute phase and value (a mouse drag); handed over like a
    // slider's edit. False (message() says why) when nothing changes.
    bool spline_move(float dphase, float dvalue);
    bool spline_set(float phase, float value);
    void spline_select_next();  // the next key of the selected prototype (wraps)
    // South on the curve: the d-pad moves the selected key (left/right phase,
    // up/down value, LB/RB 10x finer/coarser), south selects the next key, east leaves.
    bool spline_pad_mode() const { return spline_pad_; }
    void set_spline_pad_mode(bool on);

    void draw(std::int32_t width, std::int32_t height, float dt_s) override;
    void recreate() override;
    bool on_native_event(const void* event) override;

private:
    void feed_navigation();
    void draw_panel(float width, float height);
    void draw_row(std::size_t index);
    void draw_terrain_section();
    void terrain_buttons(const char* label, std::initializer_list<std::pair<const char*, TerrainAction>> buttons);
    void say(const std::string& line, bool problem);
    bool edit_prototype(const SplinePrototype& next);
    std::optional<std::string> edited_value_text(const std::string& table, const std::string& key) const;
    bool name_terrain_in_config(const std::string& terrain_path);
    void spline_pad_steps();
    void draw_spline_section(float width);
    void draw_spline_canvas(float width);

    render::Platform& platform_;
    TuningUiOptions options_;
    AppConfig defaults_;
    AppConfig working_;
    std::vector<PanelKey> keys_;
    std::vector<std::string> edited_;  // "table.key", in the order first edited
    bool pending_ = false;
    bool open_ = false;
    bool focus_first_ = false;  // just opened: the pad starts on the first editable slider
    int focus_frames_ = 0;
    std::size_t first_editable_ = 0;
    bool sdl_ = false;
    ImGuiContext* context_ = nullptr;
    std::unique_ptr<render::ImGuiGles3Renderer> renderer_;
    TickInput pad_{};
    std::uint32_t press_ = 0;     // this frame's press event
    PadStepper stepper_;
    std::uint32_t steps_ = 0;     // the step buttons ImGui sees down this frame
    std::string save_path_;
    std::array<char, 512> path_buffer_{};
    std::string message_;
    bool message_problem_ = false;
    float puppet_x_ = 0.0f, puppet_z_ = 0.0f;
    int selected_box_ = -1, selected_slope_ = -1;  // -1: none
    bool jump_to_terrain_ = false;  // west was pressed: open the terrain section, focus its first button
    int jump_frames_ = 0;
    bool jump_to_spline_ = false;    // west again: the spline editor's curve gets the focus
    bool next_jump_spline_ = false;  // west alternates: terrain editor, spline editor
    bool spline_pad_ = false;
    int spline_drag_ = -1;           // the key the mouse drags, -1: none
    float drag_lo_ = 0.0f, drag_hi_ = 1.0f;  // the curve's value range, held while dragging
};

}  // namespace marionette::ui
