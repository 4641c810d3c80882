// [motion_graph.buttons] (docs/config.md): the button → label map is read from
// config, validated with file:line:key errors, round-trips through the effective
// configuration, and is resolved against a graph's labels with the documented
// rule (a changed key must exist in the graph; a default one only warns).
#include <catch2/catch.hpp>

#include "app/config/config.hpp"
#include "app/graph/graph_files.hpp"
#include "tests/graph_fixture.hpp"
#include "tests/config_error_check.hpp"

using namespace marionette;

namespace {
std::size_t bit(Button b) { return static_cast<std::size_t>(b); }
}  // namespace

TEST_CASE("graph buttons: the shipped file maps the face buttons to the default graph's actions", "[graph_buttons]") {
    const SimConfig c = default_config().sim;
    CHECK(c.graph_buttons[bit(Button::south)].label == "jump");
    CHECK(c.graph_buttons[bit(Button::east)].label == "wave");
    CHECK(c.graph_buttons[bit(Button::west)].label == "bow");
    CHECK(c.graph_buttons[bit(Button::north)].label == "look_around");
    CHECK(c.graph_buttons[bit(Button::dpad_up)].label.empty());
    CHECK(c.graph_buttons[bit(Button::left_shoulder)].label.empty());
    CHECK(c.graph_buttons[bit(Button::south)].file == "config/marionette.toml");
    CHECK(c.graph_buttons[bit(Button::south)].line > 0);
}

TEST_CASE("graph buttons: a user file remaps buttons and the map round-trips", "[graph_buttons]") {
    const SimConfig c = apply_config_text(default_config(), "[motion_graph.buttons]\neast = \"\"\ndpad_up = \"wave\"\n", "u.toml").sim;
    CHECK(c.graph_buttons[bit(Button::east)].label.empty());
    CHECK(c.graph_buttons[bit(Button::dpad_up)].label == "wave");
    CHECK(c.graph_buttons[bit(Button::dpad_up)].file == "u.toml");
    CHECK(c.graph_buttons[bit(Button::dpad_up)].line == 3);
    CHECK(c.graph_buttons[bit(Button::south)].label == "jump");  // untouched
    const SimConfig back = config_from_text(serialize_config(c), "effective").sim;
    for (std::size_t b = 0; b < kButtonNames.size(); ++b) CHECK(back.graph_buttons[b].label == c.graph_buttons[b].label);
}

TEST_CASE("graph buttons: bad keys and values name file, line and key", "[graph_buttons]") {
    test::expect_config_error("[motion_graph.buttons]\nsouth_button = \"jump\"\n", 2, "motion_graph.buttons.south_button", "unknown button");
    test::expect_config_error("[motion_graph.buttons]\n\nnorth = 3\n", 3, "motion_graph.buttons.north", "expected a label name");
    test::expect_config_error("[motion_graph]\nbuttons = 1\n", 2, "motion_graph.buttons", "expected a table");
    test::expect_config_error("[motion_graph.buttons]\nwest = \"a\\tb\"\n", 2, "motion_graph.buttons.west", "control characters");
}

TEST_CASE("graph buttons: resolved against the graph's labels", "[graph_buttons]") {
    const MotionGraph g = test::make_locomotion_graph();  // labels walk, idle, wave
    SECTION("the default map plays what the graph has; the rest only warns") {
        const auto map = resolve_graph_buttons(default_config().sim, g, "test graph");
        CHECK(map[bit(Button::east)] == g.label_index("wave"));
        CHECK(map[bit(Button::south)] == -1);
        CHECK(map[bit(Button::north)] == -1);
        CHECK(map[bit(Button::dpad_up)] == -1);
    }
    SECTION("a changed key names a label of the graph") {
        const SimConfig c = apply_config_text(default_config(), "[motion_graph.buttons]\nsouth = \"idle\"\ndpad_left = \"walk\"\n", "u.toml").sim;
        const auto map = resolve_graph_buttons(c, g, "test graph");
        CHECK(map[bit(Button::south)] == g.label_index("idle"));
        CHECK(map[bit(Button::dpad_left)] == g.label_index("walk"));
    }
    SECTION("a changed key naming a missing label is an error with its file, line and the graph's labels") {
        const SimConfig c = apply_config_text(default_config(), "[motion_graph.buttons]\n\nright_shoulder = \"dance\"\n", "u.toml").sim;
        try {
            resolve_graph_buttons(c, g, "test graph");
            FAIL("no error");
        } catch (const ConfigError& e) {
            CHECK(e.file() == "u.toml");
            CHECK(e.line() == 3);
            CHECK(e.key() == "motion_graph.buttons.right_shoulder");
            CHECK_THAT(e.what(), Catch::Contains("'dance' is not in test graph") && Catch::Contains("walk, idle, wave"));
        }
    }
    SECTION("a graph without labels runs the default map with no error") {
        MotionGraph unlabelled = g;
        unlabelled.labels.clear();
        for (GraphClip& clip : unlabelled.clips) clip.label_mask = 0;
        const auto map = resolve_graph_buttons(default_config().sim, unlabelled, "unlabelled graph");
        for (std::size_t b = 0; b < kButtonNames.size(); ++b) CHECK(map[b] == -1);
    }
}
