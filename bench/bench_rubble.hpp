// The rubble both gait measurements walk on: 180 low boxes (0-7 cm) scattered
// over 12 m x 18 m around the path, so BM_GaitTick's times and
// marionette_tick_instructions' counts describe the same ground.
#pragma once

#include "runtime/ground/terrain.hpp"

namespace marionette {

inline Terrain bench_rubble_terrain() {
    Terrain terrain;
    for (int i = 0; i < 180; ++i) {
        const float x = static_cast<float>((i * 37) % 120) / 10.0f - 6.0f;
        const float z = static_cast<float>((i * 53) % 180) / 10.0f - 14.0f;
        terrain.boxes.push_back({x, z, x + 0.3f, z + 0.4f, 0.01f * static_cast<float>(i % 8)});
    }
    return terrain;
}

}  // namespace marionette
