// Terrain TOML: refusals are ConfigError; an accepted terrain answers ground
// queries anywhere with finite heights, and serialises to text that parses back.
#include <cmath>

#include "app/config/config.hpp"
#include "app/config/terrain_file.hpp"
#include "tests/fuzz/fuzz_support.hpp"

using namespace marionette;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    Terrain terrain;
    try {
        terrain = parse_terrain_text(fuzz::as_text(data, size), "fuzz.toml");
    } catch (const ConfigError&) {
        return 0;
    }
    const float points[][2] = {{0, 0}, {1.5f, -2.25f}, {-100, 100}, {1e6f, -1e6f}, {0.3f, 7}};
    for (const auto& p : points) {
        const GroundSample g = query_ground(terrain, p[0], p[1]);
        fuzz::fuzz_check(std::isfinite(g.height), "query_ground returned a non-finite height");
    }
    (void)max_height_along(terrain, -3, -3, 3, 3, 0.25f);
    try {
        (void)parse_terrain_text(serialize_terrain(terrain, ""), "serialized.toml");
    } catch (const ConfigError& e) {
        std::fprintf(stderr, "serialised terrain does not parse: %s\n", e.what());
        fuzz::fuzz_fail("serialize_terrain wrote text parse_terrain_text refuses");
    }
    return 0;
}
