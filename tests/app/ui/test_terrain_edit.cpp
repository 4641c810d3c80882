// The terrain editor's model (app/ui/terrain_edit.hpp): each edit changes the
// ground query as asked, every edit sequence leaves a terrain that saves and
// loads back bit for bit, and Save keeps the file's top comments.
#include <catch2/catch.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "app/config/terrain_file.hpp"
#include "app/ui/terrain_edit.hpp"

using namespace marionette;

TEST_CASE("terrain edits: a box under the puppet, moved, resized, deleted", "[ui][terrain_edit]") {
    Terrain t = load_terrain("flat");
    const std::size_t i = ui::add_box(t, 0.0f, 0.0f, 1.0f, 0.15f);
    CHECK(query_ground(t, 0.0f, 0.0f).height == Approx(0.15f));
    CHECK(query_ground(t, 0.6f, 0.0f).height == 0.0f);
    REQUIRE(ui::box_at(t, 0.2f, -0.2f) == i);
    CHECK(ui::move_box(t, i, 1.0f, 0.0f, 0.05f));
    CHECK(query_ground(t, 0.0f, 0.0f).height == 0.0f);
    CHECK(query_ground(t, 1.0f, 0.0f).height == Approx(0.2f));
    CHECK(ui::resize_box(t, i, 2.0f, 0.0f));  // 3 m wide in x, centred at x = 1
    CHECK(query_ground(t, -0.4f, 0.0f).height == Approx(0.2f));
    CHECK(ui::resize_box(t, i, -100.0f, -100.0f));  // never below the smallest side
    CHECK(t.boxes[i].max_x - t.boxes[i].min_x == Approx(ui::kMinFeatureSize));
    CHECK_FALSE(ui::move_box(t, 7, 1.0f, 0.0f, 0.0f));
    CHECK(ui::delete_box(t, i));
    CHECK(t == load_terrain("flat"));
    CHECK_FALSE(ui::delete_box(t, 0));
}

TEST_CASE("terrain edits: slopes tilt within the file's limits; the brush raises cells", "[ui][terrain_edit]") {
    Terrain t = load_terrain("flat");
    const std::size_t s = ui::add_slope(t, 0.0f, 0.0f, 2.0f, 0.1f);
    CHECK(ui::tilt_slope(t, s, 0.25f, 0.0f));
    CHECK(query_ground(t, 0.5f, 0.0f).height == Approx(0.1f + 0.25f * 1.5f));
    CHECK(ui::tilt_slope(t, s, 10.0f, -10.0f));
    CHECK(t.slopes[s].grade_x == ui::kMaxGrade);
    CHECK(t.slopes[s].grade_z == -ui::kMaxGrade);
    CHECK(ui::delete_slope(t, s));
    // No heightfield yet: the brush makes one around the puppet, then raises it.
    const int changed = ui::brush_heightfield(t, 0.0f, 0.0f, 0.5f, 0.1f);
    CHECK(changed == 13);  // grid points within 0.5 m on a 0.25 m grid: 1 + 4·2 + 4
    CHECK(t.heightfield.nx == ui::kBrushGridSide);
    CHECK(query_ground(t, 0.0f, 0.0f).height == Approx(0.1f));
    CHECK(query_ground(t, 3.0f, 3.0f).height == 0.0f);
    (void)ui::brush_heightfield(t, 0.0f, 0.0f, 0.5f, -0.1f);
    CHECK(query_ground(t, 0.0f, 0.0f).height == Approx(0.0f).margin(1e-6));
}

TEST_CASE("terrain edits: generated edit sequences save and load back bit for bit", "[ui][terrain_edit]") {
    const std::string path = "terrain_edit_test.toml";
    std::mt19937 rng(1919);  // fixed seed
    auto uniform = [&](float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); };
    const char* starts[] = {"flat", "stairs", "slope", "rubble", "hillside"};
    for (int c = 0; c < 60; ++c) {
        Terrain t = load_terrain(starts[c % 5]);
        const int edits = 1 + static_cast<int>(rng() % 25);
        for (int e = 0; e < edits; ++e) {
            const float x = uniform(-30.0f, 30.0f);
            const float z = uniform(-30.0f, 30.0f);
            const std::size_t pick = rng();
            switch (rng() % 9) {
                case 0: (void)ui::add_box(t, x, z, uniform(0.0f, 4.0f), uniform(-0.5f, 1.5f)); break;
                case 1: (void)ui::add_slope(t, x, z, uniform(0.0f, 4.0f), uniform(-0.5f, 1.5f)); break;
                case 2:
                    if (!t.boxes.empty()) (void)ui::move_box(t, pick % t.boxes.size(), uniform(-2, 2), uniform(-2, 2), uniform(-1, 1));
                    break;
                case 3:
                    if (!t.boxes.empty()) (void)ui::resize_box(t, pick % t.boxes.size(), uniform(-5, 5), uniform(-5, 5));
                    break;
                case 4: if (!t.boxes.empty()) (void)ui::delete_box(t, pick % t.boxes.size()); break;
                case 5:
                    if (!t.slopes.empty()) (void)ui::tilt_slope(t, pick % t.slopes.size(), uniform(-3, 3), uniform(-3, 3));
                    break;
                case 6:
                    if (!t.slopes.empty()) (void)ui::resize_slope(t, pick % t.slopes.size(), uniform(-5, 5), uniform(-5, 5));
                    break;
                case 7: if (!t.slopes.empty()) (void)ui::delete_slope(t, pick % t.slopes.size()); break;
                default: (void)ui::brush_heightfield(t, x, z, uniform(0.0f, 3.0f), uniform(-0.3f, 0.3f)); break;
            }
        }
        INFO("case " << c << " from " << starts[c % 5] << ", " << edits << " edits");
        REQUIRE(ui::save_terrain_file(t, path).empty());
        CHECK(load_terrain(path) == t);
    }
    std::filesystem::remove(path);
}

TEST_CASE("terrain save keeps the file's top comments and refuses no name", "[ui][terrain_edit]") {
    const std::string path = "terrain_edit_comments.toml";
    {
        std::ofstream out(path);
        out << "# my course\n# two steps\n\n[[box]]\nmin = [0.0, 0.0]\nmax = [1.0, 1.0]\ntop = 0.1\n";
    }
    Terrain t = load_terrain(path);
    (void)ui::add_box(t, 3.0f, 3.0f, 1.0f, 0.2f);
    REQUIRE(ui::save_terrain_file(t, path).empty());
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    CHECK(text.str().rfind("# my course\n# two steps\n\n", 0) == 0);
    CHECK(load_terrain(path) == t);
    CHECK_FALSE(ui::save_terrain_file(t, "").empty());
    std::filesystem::remove(path);
}
