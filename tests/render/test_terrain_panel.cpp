// The tuning panel's terrain editor (app/ui/terrain_panel.cpp): each step the
// pad's buttons make changes the working terrain as it says, is handed over as
// an edit the simulation takes at a tick boundary, and Save writes a terrain
// file that loads back bit for bit. Drawn with the section open, headless.
#include <catch2/catch.hpp>

#include <filesystem>
#include <random>
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
using A = ui::TerrainAction;

namespace {
render::PlatformOptions panel_platform() {
    render::PlatformOptions p;
    p.kind = render::PlatformKind::headless;
    p.width = 640;
    p.height = 400;
    return p;
}
}  // namespace

TEST_CASE("terrain editor steps: add under the puppet, move, raise, resize, tilt, brush, delete", "[render][ui][terrain]") {
    AppConfig base = default_config();
    base.sim.terrain = load_terrain("flat");
    base.sim.terrain_name = "flat";
    render::View view(panel_platform(), render::RenderSettings{}, make_puppet_skeleton(base.sim), base.sim.terrain);
    // Save terrain also names the file in the configuration Save writes: this test's own.
    ui::TuningUi tuning(view.platform(), ui::TuningUiOptions{base, "", "terrain_steps_tuned.toml", stderr});
    AppConfig handed;
    CHECK_FALSE(tuning.take_edit(handed));

    // Nothing selected yet: a box step is refused and says so.
    CHECK_FALSE(tuning.terrain_action(A::box_raise));
    CHECK_THAT(tuning.message(), Catch::Contains("no box selected"));

    tuning.set_puppet_position(1.0f, 2.0f);
    REQUIRE(tuning.terrain_action(A::add_box));
    CHECK(tuning.selected_box() == 0);
    const Terrain& t = tuning.working().sim.terrain;
    CHECK(query_ground(t, 1.0f, 2.0f).height == Approx(0.1f));
    REQUIRE(tuning.take_edit(handed));
    CHECK(handed.sim.terrain == t);
    // The simulation takes it live (no longer a structural change).
    Simulation sim(base.sim);
    CHECK(sim.retune(handed.sim).ok());
    CHECK(sim.terrain() == t);

    for (int i = 0; i < 3; ++i) CHECK(tuning.terrain_action(A::box_raise));
    CHECK(t.boxes[0].top == Approx(0.1f + 3 * ui::kTerrainHeightStep));
    CHECK(tuning.terrain_action(A::box_x_plus));
    CHECK(t.boxes[0].min_x == Approx(0.5f + ui::kTerrainMoveStep));
    CHECK(tuning.terrain_action(A::box_wider));
    CHECK(t.boxes[0].max_x - t.boxes[0].min_x == Approx(1.0f + ui::kTerrainMoveStep));
    CHECK(tuning.terrain_action(A::box_longer));
    CHECK(t.boxes[0].max_z - t.boxes[0].min_z == Approx(1.0f + ui::kTerrainMoveStep));

    const float under = query_ground(t, 1.0f, 2.0f).height;  // the box: a slope's base is above the ground there
    REQUIRE(tuning.terrain_action(A::add_slope));
    CHECK(tuning.terrain_action(A::slope_tilt_x_plus));
    CHECK(t.slopes[0].grade_x == Approx(ui::kTerrainGradeStep));
    CHECK(tuning.terrain_action(A::slope_raise));
    CHECK(t.slopes[0].base == Approx(under + 0.05f + ui::kTerrainHeightStep));

    tuning.set_puppet_position(-3.0f, -3.0f);
    tuning.brush_radius = 0.5f;
    REQUIRE(tuning.terrain_action(A::brush_raise));
    CHECK(query_ground(t, -3.0f, -3.0f).height == Approx(tuning.brush_step));

    // Drawn with every row: the panel open, the terrain section with it.
    tuning.set_open(true);
    for (int i = 0; i < 3; ++i) view.frame(PuppetState{}, render::DebugOverlay{}, "", 1.0f / 60.0f);

    // Save: a built-in terrain goes to a new file, which loads back as edited.
    const std::string path = tuning.terrain_save_path();
    CHECK(path == "marionette-terrain.toml");
    REQUIRE(tuning.save_terrain(path));
    CHECK(load_terrain(path) == t);
    CHECK(load_config("terrain_steps_tuned.toml").sim.terrain == t);
    std::filesystem::remove(path);
    std::filesystem::remove("terrain_steps_tuned.toml");

    CHECK(tuning.terrain_action(A::box_delete));
    CHECK(tuning.terrain_action(A::slope_delete));
    CHECK(t.boxes.empty());
    CHECK(t.slopes.empty());
    CHECK(tuning.selected_box() == -1);
    CHECK_FALSE(tuning.terrain_action(A::select_next_box));
}

TEST_CASE("generated terrain editor step sequences stay loadable and the simulation takes each", "[render][ui][terrain]") {
    AppConfig base = default_config();  // the stairs
    render::View view(panel_platform(), render::RenderSettings{}, make_puppet_skeleton(base.sim), base.sim.terrain);
    ui::TuningUi tuning(view.platform(), ui::TuningUiOptions{base, "", "terrain_west_tuned.toml", stderr});
    Simulation sim(base.sim);
    std::mt19937 rng(19);  // fixed seed
    const int last = static_cast<int>(A::brush_lower);
    int taken = 0;
    for (int step = 0; step < 400; ++step) {
        tuning.set_puppet_position(std::uniform_real_distribution<float>(-10.0f, 10.0f)(rng),
                                   std::uniform_real_distribution<float>(-10.0f, 10.0f)(rng));
        const auto action = static_cast<A>(rng() % static_cast<unsigned>(last + 1));
        (void)tuning.terrain_action(action);
        AppConfig handed;
        if (!tuning.take_edit(handed)) continue;
        ++taken;
        INFO("step " << step << ", action " << static_cast<int>(action));
        REQUIRE(sim.retune(handed.sim).ok());
        REQUIRE(parse_terrain_text(serialize_terrain(handed.sim.terrain, ""), "step") == handed.sim.terrain);
        sim.step(TickInput{});
    }
    CHECK(taken > 100);
    CHECK(sim.terrain() == tuning.working().sim.terrain);
}

TEST_CASE("west takes the pad to the terrain editor, south adds a box, down to Save terrain saves", "[render][ui][terrain]") {
    AppConfig base = default_config();  // the stairs
    render::View view(panel_platform(), render::RenderSettings{}, make_puppet_skeleton(base.sim), base.sim.terrain);
    ui::TuningUi tuning(view.platform(), ui::TuningUiOptions{base, "", "terrain_west_tuned.toml", stderr});
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
    const std::size_t boxes = base.sim.terrain.boxes.size();
    // West: the terrain editor opens with the pad on its first button, add box.
    press(Button::west);
    for (int i = 0; i < 4; ++i) frame_with(0);  // the panel settles the focus (releasing() holds presses meanwhile)
    CHECK_FALSE(tuning.releasing());
    press(Button::south);
    INFO("message: " << tuning.message());
    CHECK(tuning.working().sim.terrain.boxes.size() == boxes + 1);
    AppConfig handed;
    CHECK(tuning.take_edit(handed));
    // Down through the rows to Save terrain: box, box size, slope, slope grade, two sliders, heightfield, Save.
    for (int i = 0; i < 8; ++i) press(Button::dpad_down);
    press(Button::south);
    CHECK_THAT(tuning.message(), Catch::Contains("saved the terrain"));
    CHECK(load_terrain("marionette-terrain.toml") == tuning.working().sim.terrain);
    CHECK_THAT(read_text_file("terrain_west_tuned.toml"), Catch::Contains("name = \"marionette-terrain.toml\""));
    std::filesystem::remove("marionette-terrain.toml");
    std::filesystem::remove("terrain_west_tuned.toml");
    // No slider was touched on the way.
    CHECK(serialize_config(handed.sim) == [&] {
        SimConfig expected = base.sim;
        expected.terrain = handed.sim.terrain;
        return serialize_config(expected);
    }());
}
