// The tuning panel's spline editor (app/ui/spline_panel.cpp) through the real
// TuningUi and ImGui, headless: west twice puts the pad on the curve, south
// starts the d-pad mode, the d-pad steps the selected key; each step is handed
// over as an edit the simulation takes live; Save writes the prototype back
// into the commented file it came from. And Save terrain names the saved file
// in the configuration ([terrain] name), so `run --config` starts on it.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include "app/config/config.hpp"
#include "app/config/terrain_file.hpp"
#include "app/io/files.hpp"
#include "app/ui/pad_presses.hpp"
#include "app/ui/tuning_ui.hpp"
#include "render_es/view.hpp"
#include "runtime/gait/puppet.hpp"
#include "runtime/sim/simulation.hpp"
#include "tests/render/ui_pad_driver.hpp"

using namespace marionette;

namespace {
render::PlatformOptions panel_platform() {
    render::PlatformOptions p;
    p.kind = render::PlatformKind::headless;
    p.width = 640;
    p.height = 400;
    return p;
}

int comment_lines(const std::string& text) {
    int n = 0;
    for (std::size_t at = text.find('#'); at != std::string::npos; at = text.find('#', text.find('\n', at)))
        ++n;
    return n;
}

void write(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }
}  // namespace

TEST_CASE("the pad edits a spline key: west twice, south, d-pad; handed over, taken live, saved with the comments",
          "[render][ui][spline]") {
    const std::string path = "spline_panel_test.toml";
    const std::string original = std::string(default_config_text());
    write(path, original);
    AppConfig base = load_config(path);
    render::View view(panel_platform(), render::RenderSettings{}, make_puppet_skeleton(base.sim), base.sim.terrain);
    ui::TuningUi tuning(view.platform(), ui::TuningUiOptions{base, path, path, stderr});
    view.set_layer(&tuning);
    const PuppetState idle_state{};
    const render::DebugOverlay no_overlay{};
    test::UiPadDriver pad_driver(tuning, view, idle_state, no_overlay);
    auto frame_with = [&](std::uint32_t buttons) { pad_driver.frame(buttons); };
    auto press = [&](Button b) { pad_driver.press(b); };
    frame_with(0);
    frame_with(ui::kUiChord);
    REQUIRE(tuning.is_open());
    for (int i = 0; i < 4; ++i) frame_with(0);
    press(Button::west);  // the terrain editor
    for (int i = 0; i < 4; ++i) frame_with(0);
    press(Button::west);  // the spline editor's curve
    for (int i = 0; i < 4; ++i) frame_with(0);
    CHECK_FALSE(tuning.releasing());
    CHECK_FALSE(tuning.spline_pad_mode());
    press(Button::south);
    INFO("message: " << tuning.message());
    REQUIRE(tuning.spline_pad_mode());
    // The selected key: the walk's swing, key 1, channel y (lift).
    const PrototypeKey before = base.sim.walk.swing_foot.keys[1];
    press(Button::dpad_up);
    press(Button::dpad_up);
    press(Button::dpad_right);
    const PrototypeKey& now = tuning.working().sim.walk.swing_foot.keys[1];
    CHECK(now.y == 0.06f);  // 0.05 + 2 steps, on the 1e-4 grid
    CHECK(now.phase == 0.21f);
    CHECK(now.x == before.x);
    CHECK(now.z == before.z);
    AppConfig handed;
    REQUIRE(tuning.take_edit(handed));
    CHECK(handed.sim.walk.swing_foot == tuning.working().sim.walk.swing_foot);
    // Nothing else changed on the way (no slider, no terrain).
    SimConfig expected = base.sim;
    expected.walk.swing_foot = handed.sim.walk.swing_foot;
    CHECK(serialize_config(handed.sim) == serialize_config(expected));
    // The simulation takes it live and keeps walking on it.
    Simulation sim(base.sim);
    TickInput walk;
    walk.left_y = 32767;
    for (int i = 0; i < 60; ++i) sim.step(walk);
    CHECK(sim.retune(handed.sim).ok());
    for (int i = 0; i < 120; ++i) sim.step(walk);
    CHECK(sim.state().velocity.y != 0.0f);
    // South: next key; east leaves the d-pad mode (the d-pad navigates again).
    press(Button::south);
    CHECK(tuning.spline.key == 2);
    press(Button::east);
    CHECK_FALSE(tuning.spline_pad_mode());
    press(Button::north);  // save
    CHECK_THAT(tuning.message(), Catch::Contains("saved 1 edited key(s)"));
    const std::string saved = read_text_file(path);
    CHECK(comment_lines(saved) == comment_lines(original));
    CHECK_THAT(saved, Catch::Contains("\nswing_foot = [[0.0, 0.0, 0.0, 0.0], [0.21, 0.005, 0.06"));
    const AppConfig loaded = load_config(path);
    CHECK(loaded.sim.walk == tuning.working().sim.walk);
    CHECK(loaded.sim.run == base.sim.run);
    std::filesystem::remove(path);
}

TEST_CASE("spline_set clamps a mouse drag anywhere into a valid prototype", "[render][ui][spline]") {
    AppConfig base = default_config();
    render::View view(panel_platform(), render::RenderSettings{}, make_puppet_skeleton(base.sim), base.sim.terrain);
    ui::TuningUi tuning(view.platform(), ui::TuningUiOptions{base, "", "", stderr});
    tuning.spline = {ui::SplineGait::run, ui::SplinePath::hand, 1, 2};
    CHECK(tuning.spline_set(5.0f, 7.0f));  // far off the canvas
    const SplinePrototype& hand = tuning.working().sim.run.hand;
    CHECK(hand.keys[1].phase == 1.0f - ui::kMinKeyGap);
    CHECK(hand.keys[1].z == ui::kSplineValueLimit);
    CHECK(ui::validate_prototype(hand, ui::SplinePath::hand).empty());
    tuning.spline = {ui::SplineGait::walk, ui::SplinePath::swing_foot, 0, 1};
    CHECK_FALSE(tuning.spline_move(0.1f, 0.1f));  // the swing's first key is fixed
    CHECK_THAT(tuning.message(), Catch::Contains("nothing changed"));
}

TEST_CASE("Save terrain writes [terrain] name into the configuration file, keeping its comments", "[render][ui][terrain]") {
    const std::string config = "terrain_name_test.toml", terrain = "terrain_name_test_ground.toml";
    write(config, "# my kiosk\n[terrain]\nname = \"stairs\"   # the ground\n\n[gait]\nwalk_duty = 0.6  # slow\n");
    AppConfig base = load_config(config);
    render::View view(panel_platform(), render::RenderSettings{}, make_puppet_skeleton(base.sim), base.sim.terrain);
    ui::TuningUi tuning(view.platform(), ui::TuningUiOptions{base, config, config, stderr});
    tuning.set_puppet_position(0.5f, -3.0f);
    REQUIRE(tuning.terrain_action(ui::TerrainAction::add_box));
    REQUIRE(tuning.terrain_action(ui::TerrainAction::box_raise));
    REQUIRE(tuning.save_terrain(terrain));
    INFO(tuning.message());
    CHECK(read_text_file(config) == "# my kiosk\n[terrain]\nname = \"" + terrain +
                                        "\"   # the ground\n\n[gait]\nwalk_duty = 0.6  # slow\n");
    // `run --config` starts on the edited ground.
    const AppConfig restarted = load_config(config);
    CHECK(restarted.sim.terrain == tuning.working().sim.terrain);
    CHECK(restarted.sim.walk_duty == 0.6f);
    // A configuration with inline terrain data (which win over name) is left alone, and says so.
    write(config, "[terrain]\n[[terrain.box]]\nmin = [0.0, 0.0]\nmax = [1.0, 1.0]\ntop = 0.1\n");
    const std::string inline_text = read_text_file(config);
    CHECK_FALSE(tuning.save_terrain(terrain));
    CHECK_THAT(tuning.message(), Catch::Contains("inline"));
    CHECK(read_text_file(config) == inline_text);
    std::filesystem::remove(config);
    std::filesystem::remove(terrain);
}
