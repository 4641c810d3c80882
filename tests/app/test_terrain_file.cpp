#include <catch2/catch.hpp>

#include <cmath>

#include "app/config/config.hpp"
#include "app/config/terrain_file.hpp"
#include "tests/config_error_check.hpp"

using namespace marionette;

namespace {
void expect_error(const std::string& text, int line, const std::string& key, const std::string& message) {
    test::expect_config_error_from([](const std::string& t, const std::string& f) { parse_terrain_text(t, f); },
                                   "ground.toml", text, line, key, message);
}
}  // namespace

TEST_CASE("terrain files load heightfield, boxes and slopes", "[terrain]") {
    const Terrain t = parse_terrain_text(
        "[heightfield]\norigin = [-1, -1]\ncell = 1.0\nsize = [2, 2]\nheights = [0.0, 0.2, 0.0, 0.2]\n"
        "[[box]]\nmin = [0.5, 0.5]\nmax = [0.8, 0.9]\ntop = 0.3\n"
        "[[slope]]\nmin = [2, 2]\nmax = [3, 3]\nbase = 0.1\ngrade = [0.0, 0.25]\n",
        "t.toml");
    REQUIRE(t.boxes.size() == 1);
    REQUIRE(t.slopes.size() == 1);
    CHECK(t.heightfield.nx == 2);
    CHECK(query_ground(t, -0.5f, -0.5f).height == Approx(0.1f));
    CHECK(query_ground(t, 0.6f, 0.6f).height == Approx(0.3f));
    CHECK(query_ground(t, 2.5f, 2.5f).height == Approx(0.1f + 0.125f));
}

TEST_CASE("bad terrain files name file, line, key and what was expected", "[terrain]") {
    expect_error("[[box]]\nmin = [0, 0]\nmax = [1, 1]\ntop = \"high\"\n", 4, "box.top", "expected a number");
    expect_error("[[box]]\nmin = [0, 0]\nmax = [-1, 1]\ntop = 0.1\n", 3, "box.max", "greater than min");
    expect_error("[[box]]\nmin = [0, 0, 0]\nmax = [1, 1]\ntop = 0.1\n", 2, "box.min", "two numbers");
    expect_error("[[box]]\nmin = [0, 0]\nmax = [1, 1]\n", 1, "box.top", "missing");
    expect_error("[[box]]\nmin = [0, 0]\nmax = [1, 1]\ntop = 0.1\nheight = 2\n", 5, "box.height", "unknown key");
    expect_error("[heightfield]\norigin = [0, 0]\ncell = 1\nsize = [2, 2]\nheights = [0, 0, 0]\n", 5,
                 "heightfield.heights", "nx × nz = 4");
    expect_error("[heightfield]\norigin = [0, 0]\ncell = 0\nsize = [2, 2]\nheights = [0, 0, 0, 0]\n", 3,
                 "heightfield.cell", "must be positive");
    expect_error("[heightfield]\norigin = [0, 0]\ncell = 1\nsize = [1, 2]\nheights = [0, 0]\n", 4,
                 "heightfield.size", "[2, 4096]");
    expect_error("[[slope]]\nmin = [0, 0]\nmax = [1, 1]\nbase = 0\ngrade = [0, 5]\n", 5, "slope.grade", "within ±2");
    expect_error("\n\nhills = 3\n", 3, "hills", "unknown key");
    expect_error("[[box]\n", 1, "", "TOML syntax error");
}

TEST_CASE("terrain text round-trips bit for bit", "[terrain]") {
    const Terrain rubble = load_terrain("rubble");
    const Terrain back = parse_terrain_text(serialize_terrain(rubble, ""), "again");
    CHECK(back == rubble);
}

TEST_CASE("the shipped terrains have the features the gait is tested on", "[terrain]") {
    CHECK(load_terrain("flat") == Terrain{});
    const Terrain stairs = load_terrain("builtin:stairs");
    REQUIRE(stairs.boxes.size() > 20);
    // Walking along z the rises between neighbouring treads are 5–20 cm.
    float previous = query_ground(stairs, 0.0f, 0.0f).height;
    int rises = 0;
    for (float z = 0.0f; z > -30.0f; z -= 0.05f) {
        const float h = query_ground(stairs, 0.0f, z).height;
        if (h != previous) {
            const float rise = std::abs(h - previous);
            CHECK(rise >= 0.05f - 1e-4f);
            CHECK(rise <= 0.20f + 1e-4f);
            ++rises;
        }
        previous = h;
    }
    CHECK(rises > 20);
    const Terrain slope = load_terrain("slope");
    REQUIRE(!slope.slopes.empty());
    for (const TerrainSlope& s : slope.slopes) CHECK(std::abs(std::abs(s.grade_z) - std::tan(15.0 * 3.14159265358979 / 180.0)) < 1e-6);
    const Terrain rubble = load_terrain("rubble");
    CHECK(rubble.boxes.size() == 220);
    for (const TerrainBox& b : rubble.boxes) {
        CHECK(b.top >= 0.0f);
        CHECK(b.top <= 0.08f);
    }
    CHECK_THROWS_WITH(load_terrain("builtin:moon"), Catch::Contains("no built-in terrain named 'moon'"));
    CHECK_THROWS_WITH(load_terrain("/nonexistent/ground.toml"), Catch::Contains("cannot open the terrain file"));
}

TEST_CASE("the configuration names a terrain and carries its data inline", "[terrain][config]") {
    const SimConfig c = apply_config_text(default_config(), "[terrain]\nname = \"slope\"\n", "u.toml").sim;
    CHECK(c.terrain_name == "slope");
    CHECK(c.terrain == load_terrain("slope"));
    // The effective text alone gives the same ground, with no file to read.
    const std::string text = serialize_config(c);
    CHECK_THAT(text, Catch::Contains("[[terrain.slope]]"));
    const SimConfig back = config_from_text(text, "log").sim;
    CHECK(back.terrain == c.terrain);
    CHECK(back.terrain_name == "slope");
    CHECK(serialize_config(back) == text);
    try {
        apply_config_text(default_config(), "[terrain]\nname = \"moon.toml\"\n", "u.toml");
        FAIL("no error");
    } catch (const ConfigError& e) {
        CHECK(e.line() == 2);
        CHECK(e.key() == "terrain.name");
    }
    CHECK_THROWS_WITH(apply_config_text(default_config(), "[terrain]\nname = 3\n", "u.toml"), Catch::Contains("expected a string"));
    CHECK_THROWS_WITH(apply_config_text(default_config(), "[terrain]\nnmae = \"flat\"\n", "u.toml"),
                      Catch::Contains("terrain.nmae: unknown key"));
}
