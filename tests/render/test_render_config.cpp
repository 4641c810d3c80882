// config/render.toml: defaults, overrides, errors naming file, line and key, and
// documentation of every key in docs/render.md.
#include <catch2/catch.hpp>

#include "app/config/render_config.hpp"
#include "tests/test_support.hpp"

using namespace marionette;

TEST_CASE("the default render settings file states the built-in defaults", "[render][config]") {
    const RenderConfig rc = load_render_config("");
    const render::RenderSettings defaults;
    CHECK(rc.settings.width == defaults.width);
    CHECK(rc.settings.height == defaults.height);
    CHECK(rc.settings.msaa_samples == defaults.msaa_samples);
    CHECK(rc.settings.camera.distance_m == defaults.camera.distance_m);
    CHECK(rc.settings.camera.height_m == defaults.camera.height_m);
    CHECK(rc.settings.camera.azimuth_deg == defaults.camera.azimuth_deg);
    CHECK(rc.settings.camera.smoothing_s == defaults.camera.smoothing_s);
    CHECK(rc.settings.body_colour == defaults.body_colour);
    CHECK(rc.settings.ground_colour == defaults.ground_colour);
    CHECK(rc.settings.show_hud == defaults.show_hud);
    CHECK(rc.settings.show_skeleton == defaults.show_skeleton);
    CHECK(rc.kms.policy == render::KmsModePolicy::preferred);
    CHECK(rc.kms.width == 0);
}

TEST_CASE("a render settings override changes only the keys it names", "[render][config]") {
    const RenderConfig base = load_render_config("");
    const RenderConfig rc = apply_render_config_text(
        base, "[display]\nwidth = 800\nheight = 480\n[colours]\nbody = [1, 0.5, 0]\n[kms]\nmode = \"1920x1080@144\"\npolicy = \"highest_refresh\"\n",
        "mine.toml");
    CHECK(rc.settings.width == 800);
    CHECK(rc.settings.height == 480);
    CHECK(rc.settings.msaa_samples == base.settings.msaa_samples);
    CHECK(rc.settings.body_colour == vec3(1.0f, 0.5f, 0.0f));
    CHECK(rc.kms.width == 1920);
    CHECK(rc.kms.height == 1080);
    CHECK(rc.kms.refresh_hz == 144);
    CHECK(rc.kms.policy == render::KmsModePolicy::highest_refresh);
}

TEST_CASE("bad render settings name the file, line and key", "[render][config]") {
    const RenderConfig base;
    auto error_of = [&](const std::string& text) {
        try {
            apply_render_config_text(base, text, "bad.toml");
        } catch (const ConfigError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    CHECK(error_of("[display]\n\nwidth = 3\n") == "bad.toml:3: display.width: expected an integer in [16, 16384]");
    CHECK(error_of("[colours]\nsky = [0.1, 2.0, 0.3]\n") ==
          "bad.toml:2: colours.sky: expected a colour [r, g, b] of three numbers in [0, 1]");
    CHECK(error_of("[overlays]\nhud = 1\n") == "bad.toml:2: overlays.hud: expected true or false");
    CHECK(error_of("[camera]\nzoom = 2\n").rfind("bad.toml:2: camera.zoom: unknown key (expected one of: distance_m", 0) == 0);
    CHECK(error_of("[lights]\nsun = 1\n").rfind("bad.toml:1: lights: unknown table", 0) == 0);
    CHECK(error_of("[kms]\nmode = \"big\"\n") ==
          "bad.toml:2: kms.mode: expected WIDTHxHEIGHT or WIDTHxHEIGHT@HZ (e.g. 1920x1080@60), got \"big\"");
    CHECK(error_of("[kms]\npolicy = \"fast\"\n") == "bad.toml:2: kms.policy: expected \"preferred\" or \"highest_refresh\", got \"fast\"");
    CHECK(error_of("[display\n").rfind("bad.toml:1: TOML syntax error", 0) == 0);
}

TEST_CASE("mode text parses WIDTHxHEIGHT and WIDTHxHEIGHT@HZ only", "[render][config]") {
    render::KmsModeRequest r;
    CHECK(parse_mode_text("1280x800", r));
    CHECK((r.width == 1280 && r.height == 800 && r.refresh_hz == 0));
    CHECK(parse_mode_text("2560x1440@165", r));
    CHECK(r.refresh_hz == 165);
    for (const char* bad : {"", "1280", "1280x", "x800", "1280x800@", "1280x800@0", "0x800", "1280X800", "1280x800 "})
        CHECK_FALSE(parse_mode_text(bad, r));
}

TEST_CASE("every render setting is documented in docs/render.md", "[render][config]") {
    const std::string doc = test::read_text_file(test::source_path("docs/render.md"));
    for (const ConfigKeyInfo& k : render_config_schema()) {
        INFO(k.table << "." << k.key);
        CHECK(doc.find("`" + k.key + "`") != std::string::npos);
        CHECK(doc.find("[" + k.table + "]") != std::string::npos);
    }
}

TEST_CASE("[render] character and the [character] role map: paths, roles and errors", "[render][config][character]") {
    const RenderConfig base = load_render_config("");
    CHECK(base.character.empty());  // the capsule puppet is the default
    // A relative path is resolved against the folder of the file that names it.
    const RenderConfig rc = apply_render_config_text(base,
                                                     "[render]\ncharacter = \"chars/me.glb\"\n"
                                                     "[character]\nthigh_l = \"LeftUpLeg\"\nhead = \"Head\"\n",
                                                     "/etc/marionette/render.toml");
    CHECK(rc.character == "/etc/marionette/chars/me.glb");
    REQUIRE(rc.character_map.size() == 2);
    REQUIRE(rc.character_map_lines.size() == 2);
    // toml++ gives a table's keys in its own order: look each role up.
    for (std::size_t i = 0; i < 2; ++i) {
        const auto& [role, joint] = rc.character_map[i];
        CHECK(joint == (role == "thigh_l" ? "LeftUpLeg" : "Head"));
        CHECK(rc.character_map_lines[i] == (role == "thigh_l" ? 4 : 5));
    }
    CHECK(rc.character_origin == "/etc/marionette/render.toml");
    CHECK(apply_render_config_text(base, "[render]\ncharacter = \"/abs/c.gltf\"\n", "x/render.toml").character == "/abs/c.gltf");
    try {
        apply_render_config_text(base, "[character]\nknee_l = \"LeftLeg\"\n", "mine.toml");
        FAIL("an unknown role was accepted");
    } catch (const ConfigError& e) {
        const std::string what = e.what();
        CHECK(what.find("mine.toml:2") != std::string::npos);
        CHECK(what.find("character.knee_l") != std::string::npos);
        CHECK(what.find("unknown role") != std::string::npos);
    }
    CHECK_THROWS_AS(apply_render_config_text(base, "[character]\nhead = 3\n", "mine.toml"), ConfigError);
    CHECK_THROWS_AS(apply_render_config_text(base, "[render]\ncharacter = 3\n", "mine.toml"), ConfigError);
}
