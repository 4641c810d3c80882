// The spline editor's model (app/ui/spline_edit.hpp): every edit, however wild,
// leaves the walk and run prototypes valid for the configuration loader, and a
// saved prototype (toml_edit into the commented default file) loads back equal
// bit for bit, with the file's comments in place.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "app/config/config.hpp"
#include "app/ui/spline_edit.hpp"
#include "app/ui/toml_edit.hpp"

using namespace marionette;
using ui::SplineGait;
using ui::SplinePath;

namespace {
constexpr SplineGait kGaits[] = {SplineGait::walk, SplineGait::run};
constexpr SplinePath kPaths[] = {SplinePath::swing_foot, SplinePath::pelvis, SplinePath::hand};

int count_comment_lines(const std::string& text) {
    int n = 0;
    std::size_t at = 0;
    while (at < text.size()) {
        std::size_t end = text.find('\n', at);
        if (end == std::string::npos) end = text.size();
        const std::string line = text.substr(at, end - at);
        if (line.find('#') != std::string::npos) ++n;
        at = end + 1;
    }
    return n;
}
}  // namespace

TEST_CASE("spline edits move a key by steps, clamped between its neighbours and within range", "[spline_edit]") {
    GaitConfig g;
    SplinePrototype& swing = ui::prototype_of(g, SplineGait::walk, SplinePath::swing_foot);
    REQUIRE(swing.keys[1].y == 0.05f);
    CHECK(ui::move_key(swing, SplinePath::swing_foot, 1, 0.0f, 1, ui::kSplineValueStep));
    CHECK(swing.keys[1].y == 0.055f);  // on the 1e-4 grid
    // Phase: the key never reaches its neighbour (0.5), it stops kMinKeyGap short.
    CHECK(ui::move_key(swing, SplinePath::swing_foot, 1, 5.0f, 1, 0.0f));
    CHECK(swing.keys[1].phase == 0.5f - ui::kMinKeyGap);
    CHECK_FALSE(ui::move_key(swing, SplinePath::swing_foot, 1, 1.0f, 1, 0.0f));  // already there
    CHECK(ui::move_key(swing, SplinePath::swing_foot, 1, -5.0f, 1, 0.0f));
    CHECK(swing.keys[1].phase == 0.0f + ui::kMinKeyGap);
    // Values within ±kSplineValueLimit.
    CHECK(ui::move_key(swing, SplinePath::swing_foot, 2, 0.0f, 0, -100.0f));
    CHECK(swing.keys[2].x == -ui::kSplineValueLimit);
    // The swing's end keys are fixed ([0, 0, 0, 0] and [1, 0, 0, 1]).
    CHECK_FALSE(ui::move_key(swing, SplinePath::swing_foot, 0, 0.1f, 1, 0.1f));
    CHECK_FALSE(ui::move_key(swing, SplinePath::swing_foot, 4, -0.1f, 2, 0.1f));
    // Not finite, or no such key or channel: refused, nothing changes.
    const SplinePrototype before = swing;
    CHECK_FALSE(ui::move_key(swing, SplinePath::swing_foot, 1, std::numeric_limits<float>::quiet_NaN(), 1, 0.0f));
    CHECK_FALSE(ui::set_key(swing, SplinePath::swing_foot, 1, 0.3f, 1, std::numeric_limits<float>::infinity()));
    CHECK_FALSE(ui::move_key(swing, SplinePath::swing_foot, 5, 0.0f, 1, 0.01f));
    CHECK_FALSE(ui::move_key(swing, SplinePath::swing_foot, -1, 0.0f, 1, 0.01f));
    CHECK_FALSE(ui::move_key(swing, SplinePath::swing_foot, 1, 0.0f, 3, 0.01f));
    CHECK(swing == before);
    // A looping path's end keys are one point: both move, their phases stay 0 and 1.
    SplinePrototype& pelvis = ui::prototype_of(g, SplineGait::run, SplinePath::pelvis);
    CHECK(ui::move_key(pelvis, SplinePath::pelvis, 0, 0.3f, 1, 0.01f));
    CHECK(pelvis.keys[0].phase == 0.0f);
    CHECK(pelvis.keys[3].phase == 1.0f);
    CHECK(pelvis.keys[0].y == -0.01f + 0.01f);
    CHECK(pelvis.keys[3].y == pelvis.keys[0].y);
    CHECK(ui::validate_prototype(pelvis, SplinePath::pelvis).empty());
    CHECK(ui::validate_prototype(swing, SplinePath::swing_foot).empty());
    // What validate refuses is what the loader refuses.
    SplinePrototype bad = pelvis;
    bad.keys[3].y += 0.01f;
    CHECK_THAT(ui::validate_prototype(bad, SplinePath::pelvis), Catch::Contains("looping"));
    CHECK_THROWS_WITH(apply_config_text(default_config(), "[gait.run]\npelvis = " + ui::prototype_toml(bad) + "\n", "t.toml"),
                      Catch::Contains("looping"));
}

TEST_CASE("generated spline edit sequences stay valid, load, and save back equal with the comments", "[spline_edit]") {
    std::mt19937 rng(1919);
    std::uniform_int_distribution<int> gait_d(0, 1), path_d(0, 2), key_d(-1, 8), channel_d(-1, 3), kind_d(0, 9),
        len_d(1, 40);
    std::uniform_real_distribution<float> step(-3.0f, 3.0f), wild(-200.0f, 200.0f), unit(-0.2f, 1.2f);
    const std::string file = std::string(default_config_text());
    const int comments = count_comment_lines(file);
    int applied = 0, refused = 0;
    for (int sequence = 0; sequence < 300; ++sequence) {
        AppConfig config = default_config();
        const int edits = len_d(rng);
        std::string text = file;
        for (int e = 0; e < edits; ++e) {
            const SplineGait gait = kGaits[gait_d(rng)];
            const SplinePath path = kPaths[path_d(rng)];
            SplinePrototype p = ui::prototype_of(config.sim, gait, path);
            const int key = key_d(rng), channel = channel_d(rng), kind = kind_d(rng);
            bool changed = false;
            if (kind < 6) {  // pad steps, 0.1x … 3x
                changed = ui::move_key(p, path, key, step(rng) * ui::kSplinePhaseStep, channel, step(rng) * ui::kSplineValueStep);
            } else if (kind < 8) {  // a mouse drag anywhere, off the canvas too
                changed = ui::set_key(p, path, key, unit(rng), channel, wild(rng) * 0.01f);
            } else if (kind == 8) {  // far out of range
                changed = ui::move_key(p, path, key, wild(rng), channel, wild(rng));
            } else {  // not a number
                changed = ui::move_key(p, path, key, std::numeric_limits<float>::quiet_NaN(), channel, 0.0f);
                CHECK_FALSE(changed);
            }
            INFO("sequence " << sequence << " edit " << e << ": " << ui::gait_table(gait) << "." << ui::path_key(path)
                             << " key " << key << " channel " << channel << " kind " << kind << " -> "
                             << ui::prototype_toml(p));
            REQUIRE(ui::validate_prototype(p, path).empty());
            if (!changed) {
                CHECK(p == ui::prototype_of(config.sim, gait, path));
                ++refused;
                continue;
            }
            ++applied;
            // The loader takes it (the UI's edit path) and reads back the same bits.
            const std::string edit = std::string("[") + ui::gait_table(gait) + "]\n" + ui::path_key(path) + " = " +
                                     ui::prototype_toml(p) + "\n";
            config = apply_config_text(config, edit, "generated edit");
            REQUIRE(ui::prototype_of(config.sim, gait, path) == p);
            // Save: into the commented file, value for value.
            text = ui::set_toml_value(text, ui::gait_table(gait), ui::path_key(path), ui::prototype_toml(p));
        }
        INFO("sequence " << sequence);
        const AppConfig loaded = config_from_text(text, "saved.toml");
        CHECK(loaded.sim.walk == config.sim.walk);
        CHECK(loaded.sim.run == config.sim.run);
        CHECK(count_comment_lines(text) == comments);
        CHECK(serialize_config(loaded.sim) == serialize_config(config.sim));
    }
    // With this seed: 1097 edits applied, the rest refused (no such key or
    // channel, a fixed end key, NaN, already at the limit).
    CHECK(applied == 1097);
    CHECK(refused > 1000);
}

TEST_CASE("a prototype written over several lines is replaced whole, its trailing comment kept", "[spline_edit]") {
    const std::string text =
        "# mine\n"
        "[gait.walk]   # the walk\n"
        "hand = [\n"
        "  [0.0, 0.02, 0.0, -0.12],   # back\n"
        "  [0.5, 0.02, 0.03, 0.14],\n"
        "  [1.0, 0.02, 0.0, -0.12],\n"
        "]   # arm swing\n"
        "pelvis = [[0.0, 0.0, -0.012, 0.0], [0.5, 0.015, 0.012, 0.0], [1.0, 0.0, -0.012, 0.0]]\n";
    SplinePrototype hand = default_walk_prototypes().hand;
    REQUIRE(ui::move_key(hand, SplinePath::hand, 1, 0.0f, 2, 0.01f));
    const std::string out = ui::set_toml_value(text, "gait.walk", "hand", ui::prototype_toml(hand));
    CHECK(out ==
          "# mine\n"
          "[gait.walk]   # the walk\n"
          "hand = " + ui::prototype_toml(hand) + " # arm swing\n"
          "pelvis = [[0.0, 0.0, -0.012, 0.0], [0.5, 0.015, 0.012, 0.0], [1.0, 0.0, -0.012, 0.0]]\n");
    CHECK(config_from_text(out, "t.toml").sim.walk.hand == hand);
    CHECK(config_from_text(text, "t.toml").sim.walk.hand == default_walk_prototypes().hand);
}
