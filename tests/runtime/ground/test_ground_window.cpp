// GroundWindow: queries through a window of gathered boxes give exactly the
// terrain's own results (height and normal, bit for bit), inside the window,
// outside it and when it overflowed. Generated cases, fixed seed: terrains of
// 0 to 300 boxes (overlapping, nested, degenerate, NaN-bounded), slopes and a
// heightfield; windows small, large, empty and inverted; points inside, on the
// edges and outside.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "runtime/ground/terrain.hpp"

using namespace marionette;

namespace {
bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same_sample(const GroundSample& a, const GroundSample& b) {
    return same_bits(a.height, b.height) && same_bits(a.normal.x, b.normal.x) && same_bits(a.normal.y, b.normal.y) &&
           same_bits(a.normal.z, b.normal.z);
}

Terrain random_terrain(std::mt19937& rng) {
    std::uniform_real_distribution<float> at(-3.0f, 3.0f), size(0.0f, 1.5f), top(-0.2f, 0.6f), grade(-0.5f, 0.5f);
    std::uniform_int_distribution<int> boxes(0, 300), slopes(0, 3), pick(0, 19);
    Terrain t;
    const int nb = boxes(rng);
    for (int i = 0; i < nb; ++i) {
        const float x = at(rng), z = at(rng);
        TerrainBox b{x, z, x + size(rng), z + size(rng), top(rng)};
        const int kind = pick(rng);
        if (kind == 0) b.max_x = b.min_x;                                        // zero width
        if (kind == 1) b.top = b.top < 0.1f ? 0.1f : b.top;                       // ties between boxes
        if (kind == 2) b.min_x = std::numeric_limits<float>::quiet_NaN();        // holds no point
        if (kind == 3) b.max_z = b.min_z - 0.5f;                                  // inverted: holds no point
        if (kind == 4) b.top = 0.25f;                                            // exact ties
        t.boxes.push_back(b);
    }
    const int ns = slopes(rng);
    for (int i = 0; i < ns; ++i) {
        const float x = at(rng), z = at(rng);
        t.slopes.push_back({x, z, x + 2.0f * size(rng), z + 2.0f * size(rng), top(rng), grade(rng), grade(rng)});
    }
    if (pick(rng) < 5) t.heightfield = {-2.0f, -2.0f, 0.5f, 9, 9, std::vector<float>(81, 0.0f)};
    for (float& h : t.heightfield.heights) h = 0.3f * grade(rng);
    return t;
}
}  // namespace

TEST_CASE("a ground window answers every query as its terrain does", "[terrain][ground_window]") {
    std::mt19937 rng(20);
    std::uniform_real_distribution<float> at(-4.0f, 4.0f), extent(0.0f, 2.5f), unit(0.0f, 1.0f);
    std::uniform_int_distribution<int> pick(0, 9);
    int windows = 0, overflowed = 0, points = 0, level = 0;
    for (int c = 0; c < 400; ++c) {
        const Terrain t = random_terrain(rng);
        for (int w = 0; w < 4; ++w) {
            float x0 = at(rng), z0 = at(rng);
            float x1 = x0 + extent(rng), z1 = z0 + extent(rng);
            const int kind = pick(rng);
            if (kind == 0) x1 = x0, z1 = z0;                    // a point
            if (kind == 1) std::swap(x0, x1);                  // inverted: nothing is inside
            if (kind == 2) x0 = -10.0f, z0 = -10.0f, x1 = 10.0f, z1 = 10.0f;  // everything: overflows past 64 boxes
            const GroundWindow win = ground_window(t, x0, z0, x1, z1);
            ++windows;
            overflowed += win.overflow ? 1 : 0;
            level += win.level ? 1 : 0;
            for (int p = 0; p < 60; ++p) {
                float x = at(rng), z = at(rng);
                const int where = pick(rng);
                if (where < 5) x = x0 + (x1 - x0) * unit(rng), z = z0 + (z1 - z0) * unit(rng);  // inside
                if (where == 5) x = x0, z = z1;                                                  // on a corner
                if (where == 6) x = std::nextafter(x1, 1e9f), z = z0;                            // just outside
                if (where == 7) x = std::numeric_limits<float>::quiet_NaN();
                ++points;
                INFO("case " << c << " window " << w << " point " << p << " at " << x << ", " << z);
                REQUIRE(same_sample(query_ground(win, x, z), query_ground(t, x, z)));
                const float xe = x + 0.3f * (unit(rng) - 0.5f), ze = z + 0.3f * (unit(rng) - 0.5f);
                REQUIRE(same_bits(max_height_along(win, x, z, xe, ze, 0.01f), max_height_along(t, x, z, xe, ze, 0.01f)));
            }
        }
    }
    CHECK(windows == 1600);
    CHECK(points == 96000);
    CHECK(overflowed > 0);  // the overflow path was exercised
    CHECK(level > 20);      // … and the level window's, which skips the scan inside it
}

// A window is level (its inside answered without a scan) only when no box,
// slope or heightfield reaches it. A slope with a NaN bound holds no point; the
// overlap test may still count it (then the full query answers, the same).
TEST_CASE("a ground window is level only where nothing but level ground reaches it", "[terrain][ground_window]") {
    Terrain t;
    CHECK(ground_window(t, -1.0f, -1.0f, 1.0f, 1.0f).level);  // flat terrain
    t.boxes.push_back({5.0f, 5.0f, 6.0f, 6.0f, 0.2f});
    t.slopes.push_back({-6.0f, -6.0f, -5.0f, -5.0f, 0.0f, 0.1f, 0.0f});
    const GroundWindow away = ground_window(t, -1.0f, -1.0f, 1.0f, 1.0f);
    CHECK(away.level);
    CHECK(query_ground(away, 0.5f, 0.5f).height == 0.0f);
    CHECK(query_ground(away, 5.5f, 5.5f).height == 0.2f);  // outside the window: the whole terrain
    CHECK_FALSE(ground_window(t, 4.0f, 4.0f, 5.0f, 5.0f).level);     // touches the box (closed edges)
    CHECK_FALSE(ground_window(t, -5.5f, -5.5f, 0.0f, 0.0f).level);   // holds part of the slope
    Terrain nan_slope;
    nan_slope.slopes.push_back({std::numeric_limits<float>::quiet_NaN(), 0.0f, 1.0f, 1.0f, 0.0f, 0.1f, 0.0f});
    const GroundWindow beside_nan = ground_window(nan_slope, -1.0f, -1.0f, 2.0f, 2.0f);
    CHECK(query_ground(beside_nan, 0.5f, 0.5f).height == query_ground(nan_slope, 0.5f, 0.5f).height);
    Terrain field;
    field.heightfield = {20.0f, 20.0f, 0.5f, 3, 3, std::vector<float>(9, 0.3f)};  // far away, but read clamped everywhere
    CHECK_FALSE(ground_window(field, -1.0f, -1.0f, 1.0f, 1.0f).level);
    CHECK(query_ground(ground_window(field, -1.0f, -1.0f, 1.0f, 1.0f), 0.0f, 0.0f).height == query_ground(field, 0.0f, 0.0f).height);
}

TEST_CASE("a ground window gathers only the boxes overlapping it, in order", "[terrain][ground_window]") {
    Terrain t;
    t.boxes.push_back({0.0f, 0.0f, 1.0f, 1.0f, 0.1f});    // overlaps
    t.boxes.push_back({5.0f, 5.0f, 6.0f, 6.0f, 0.2f});    // far away
    t.boxes.push_back({1.5f, -1.0f, 2.0f, 0.0f, 0.3f});   // touches the window's corner (closed edges)
    t.boxes.push_back({0.5f, 0.5f, 0.7f, 0.7f, 0.3f});    // inside
    const GroundWindow w = ground_window(t, 0.5f, 0.0f, 1.5f, 2.0f);
    REQUIRE_FALSE(w.overflow);
    REQUIRE(w.count == 3);
    CHECK(w.boxes[0] == 0);
    CHECK(w.boxes[1] == 2);
    CHECK(w.boxes[2] == 3);
    CHECK(query_ground(w, 5.5f, 5.5f).height == 0.2f);  // outside the window: the whole terrain
    CHECK(query_ground(w, 0.6f, 0.6f).height == 0.3f);
}
