#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "runtime/ground/terrain.hpp"

using namespace marionette;

TEST_CASE("flat terrain is height 0 with an upward normal", "[terrain]") {
    const Terrain flat;
    const GroundSample g = query_ground(flat, 3.0f, -7.0f);
    CHECK(g.height == 0.0f);
    CHECK(g.normal.y == 1.0f);
}

TEST_CASE("boxes and slopes raise the surface inside their footprint only", "[terrain]") {
    Terrain t;
    t.boxes.push_back({0.0f, 1.0f, 1.0f, 1.3f, 0.15f});
    t.slopes.push_back({-2.0f, 0.0f, -1.0f, 4.0f, 0.0f, 0.0f, 0.25f});
    CHECK(query_ground(t, 0.5f, 1.1f).height == Approx(0.15f));
    CHECK(query_ground(t, 0.5f, 1.4f).height == 0.0f);
    const GroundSample s = query_ground(t, -1.5f, 2.0f);
    CHECK(s.height == Approx(0.5f));
    // Normal of the plane y = 0.25 z is (0, 1, -0.25) normalised.
    CHECK(s.normal.z == Approx(-0.25f / std::sqrt(1.0625f)));
    CHECK(s.normal.y == Approx(1.0f / std::sqrt(1.0625f)));
}

TEST_CASE("heightfield interpolates bilinearly and clamps outside", "[terrain]") {
    Terrain t;
    t.heightfield = {0.0f, 0.0f, 1.0f, 2, 2, {0.0f, 1.0f, 2.0f, 3.0f}};
    CHECK(query_ground(t, 0.5f, 0.5f).height == Approx(1.5f));  // mean of the four corners
    CHECK(query_ground(t, 0.25f, 0.0f).height == Approx(0.25f));
    CHECK(query_ground(t, -5.0f, 9.0f).height == Approx(2.0f));  // nearest corner (0, 1)
    const GroundSample g = query_ground(t, 0.5f, 0.5f);
    // h = x + 2z: normal ∝ (-1, 1, -2).
    CHECK(g.normal.x == Approx(-1.0f / std::sqrt(6.0f)));
    CHECK(g.normal.z == Approx(-2.0f / std::sqrt(6.0f)));
}

// Found by the ground window's generated cases (case 3): a NaN coordinate on a
// heightfield terrain converted NaN to an int and read outside the heights.
TEST_CASE("a NaN point on a heightfield reads the grid's edge, never outside it", "[terrain]") {
    Terrain t;
    t.heightfield = {0.0f, 0.0f, 1.0f, 2, 2, {0.0f, 1.0f, 2.0f, 3.0f}};
    const float nan = std::numeric_limits<float>::quiet_NaN();
    CHECK(query_ground(t, nan, 0.0f).height == 0.0f);
    CHECK(query_ground(t, 1.0f, nan).height == 1.0f);
    CHECK(query_ground(t, nan, nan).normal.y == 1.0f);
    CHECK(max_height_along(t, nan, 0.0f, 1.0f, 1.0f, 0.1f) == 3.0f);
}

TEST_CASE("max_height_along finds a step between the ends", "[terrain]") {
    Terrain t;
    t.boxes.push_back({-1.0f, 0.40f, 1.0f, 0.45f, 0.2f});
    CHECK(max_height_along(t, 0.0f, 0.0f, 0.0f, 1.0f, 0.02f) == Approx(0.2f));
    CHECK(max_height_along(t, 0.0f, 0.0f, 0.0f, 0.3f, 0.02f) == 0.0f);
}
