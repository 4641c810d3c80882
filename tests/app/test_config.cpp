#include <catch2/catch.hpp>

#include "app/config/config.hpp"
#include "app/config/terrain_file.hpp"
#include "tests/config_error_check.hpp"
#include "tests/test_support.hpp"

using namespace marionette;

TEST_CASE("the shipped default file gives the built-in defaults", "[config]") {
    const SimConfig loaded = default_config().sim;
    SimConfig builtin;
    // The one deliberate difference: the runtime's default ground is flat, the
    // shipped file walks the demo over the stairs.
    builtin.terrain_name = "stairs";
    builtin.terrain = load_terrain("stairs");
    CHECK(serialize_config(loaded) == serialize_config(builtin));
    // The parts the tick never reads (not in the effective text) match too.
    CHECK(default_config().realtime == RealtimeConfig{});
    CHECK(default_config().graph_build == GraphBuildConfig{});
    // The file in the tree is the one compiled in.
    CHECK(test::read_text_file(test::source_path("config/marionette.toml")) == std::string(default_config_text()));
}

TEST_CASE("a user file overrides only what it names", "[config]") {
    const SimConfig c = apply_config_text(default_config(), "[locomotion]\nmax_speed = 2\nturn_rate_deg_s = 90.5\n", "u.toml").sim;
    CHECK(c.max_speed == 2.0f);
    CHECK(c.turn_rate_deg_s == 90.5f);
    CHECK(c.tick_rate_hz == 240);
    CHECK(c.stick_deadzone == SimConfig{}.stick_deadzone);
}

TEST_CASE("bad configuration names file, line, key and what was expected", "[config]") {
    test::expect_config_error("[locomotion]\nmax_sped = 2.0\n", 2, "locomotion.max_sped", "unknown key");
    test::expect_config_error("[locomotoin]\nmax_speed = 2.0\n", 1, "locomotoin", "unknown table");
    test::expect_config_error("\n[simulation]\ntick_rate_hz = \"fast\"\n", 3, "simulation.tick_rate_hz", "expected an integer in [30.0, 2000.0]");
    test::expect_config_error("[simulation]\ntick_rate_hz = 240.5\n", 2, "simulation.tick_rate_hz", "expected an integer");
    test::expect_config_error("[simulation]\ntick_rate_hz = 5\n", 2, "simulation.tick_rate_hz", "5 is out of range");
    test::expect_config_error("[locomotion]\nstick_deadzone = 0.95\n", 2, "locomotion.stick_deadzone", "out of range");
    test::expect_config_error("[locomotion]\nmax_speed = nan\n", 2, "locomotion.max_speed", "out of range");
    test::expect_config_error("[locomotion]\nmax_speed = true\n", 2, "locomotion.max_speed", "expected a number");
    test::expect_config_error("[locomotion\nmax_speed = 1\n", 1, "", "TOML syntax error");
    test::expect_config_error("max_speed = 1\n", 1, "max_speed", "unknown table");
    test::expect_config_error("[puppet]\npelvis_height = 1.2\n", 2, "puppet.pelvis_height", "feet cannot reach");
}

TEST_CASE("a missing user file is a clear error", "[config]") {
    CHECK_THROWS_WITH(load_config("/nonexistent/marionette.toml"), Catch::Contains("cannot open the configuration file"));
}

TEST_CASE("the effective configuration round-trips bit for bit", "[config]") {
    SimConfig c;
    c.max_speed = 2.7182817f;
    c.stick_deadzone = 0.1f;
    c.turn_rate_deg_s = 123.456f;
    c.tick_rate_hz = 1000;
    const std::string text = serialize_config(c);
    const SimConfig back = config_from_text(text, "effective").sim;
    CHECK(serialize_config(back) == text);
    CHECK(back.max_speed == c.max_speed);
    CHECK(back.stick_deadzone == c.stick_deadzone);
    CHECK(back.turn_rate_deg_s == c.turn_rate_deg_s);
    CHECK(back.tick_rate_hz == 1000);
}

TEST_CASE("every key is documented in docs/config.md", "[config]") {
    const std::string doc = test::read_text_file(test::source_path("docs/config.md"));
    for (const ConfigKeyInfo& k : config_schema()) {
        INFO(k.table << "." << k.key);
        CHECK(doc.find("`" + k.key + "`") != std::string::npos);
        CHECK(doc.find("[" + k.table + "]") != std::string::npos);
    }
}
