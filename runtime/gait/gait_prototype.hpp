#pragma once
// Spline prototypes for the gait (docs/gait.md): the shape of a swing-foot path,
// the pelvis path and the hand paths, for walking and for running, as a few keys
// each. The gait evaluates both prototypes as cubic Hermite splines (tangents
// from neighbouring keys, Catmull–Rom style), blends them with a factor that
// follows speed, and fits the result to the step being taken. Plain fixed-size
// data, so it lives in SimConfig and is edited by hand in the TOML.
#include <array>
#include <cstdint>
#include <initializer_list>

namespace marionette {

inline constexpr int kMaxPrototypeKeys = 8;

// One key: a phase in [0, 1] and three values whose meaning depends on the path.
struct PrototypeKey {
    float phase = 0.0f;
    float x = 0.0f;
    float y = 0.0f;
    float z = 0.0f;
    friend bool operator==(const PrototypeKey&, const PrototypeKey&) = default;
};

struct SplinePrototype {
    std::int32_t count = 0;
    std::array<PrototypeKey, kMaxPrototypeKeys> keys{};
    friend bool operator==(const SplinePrototype&, const SplinePrototype&) = default;
};

// swing_foot: phase = swing progress; x = sideways (m, outward), y = lift above the
//   line from lift-off to landing (m), z = fraction of the step covered (0 → 1).
// pelvis: phase = step phase (0 at each foot contact); x = sway toward the stance
//   foot (m), y = vertical bob (m), z = forward surge (m). Loops.
// hand: phase = cycle phase from the same-side foot's contact (two steps);
//   x = outward, y = up, z = forward of the hanging wrist (m). Loops.
struct GaitPrototypes {
    SplinePrototype swing_foot;
    SplinePrototype pelvis;
    SplinePrototype hand;
    friend bool operator==(const GaitPrototypes&, const GaitPrototypes&) = default;
};

inline SplinePrototype make_prototype(std::initializer_list<PrototypeKey> keys) {
    SplinePrototype p;
    for (const PrototypeKey& k : keys)
        if (p.count < kMaxPrototypeKeys) p.keys[static_cast<std::size_t>(p.count++)] = k;
    return p;
}

inline GaitPrototypes default_walk_prototypes() {
    return {make_prototype({{0.0f, 0.0f, 0.0f, 0.0f}, {0.2f, 0.005f, 0.05f, 0.1f}, {0.5f, 0.01f, 0.075f, 0.5f},
                            {0.8f, 0.005f, 0.04f, 0.9f}, {1.0f, 0.0f, 0.0f, 1.0f}}),
            make_prototype({{0.0f, 0.0f, -0.012f, 0.0f}, {0.25f, 0.01f, 0.0f, 0.005f}, {0.5f, 0.015f, 0.012f, 0.0f},
                            {0.75f, 0.01f, 0.0f, -0.005f}, {1.0f, 0.0f, -0.012f, 0.0f}}),
            make_prototype({{0.0f, 0.02f, 0.0f, -0.12f}, {0.5f, 0.02f, 0.03f, 0.14f}, {1.0f, 0.02f, 0.0f, -0.12f}})};
}

inline GaitPrototypes default_run_prototypes() {
    return {make_prototype({{0.0f, 0.0f, 0.0f, 0.0f}, {0.2f, 0.005f, 0.08f, 0.12f}, {0.5f, 0.01f, 0.12f, 0.5f},
                            {0.8f, 0.005f, 0.06f, 0.9f}, {1.0f, 0.0f, 0.0f, 1.0f}}),
            make_prototype({{0.0f, 0.0f, -0.01f, 0.0f}, {0.3f, 0.008f, -0.025f, 0.0f}, {0.65f, 0.005f, 0.02f, 0.0f},
                            {1.0f, 0.0f, -0.01f, 0.0f}}),
            make_prototype({{0.0f, 0.03f, 0.12f, -0.15f}, {0.5f, 0.03f, 0.2f, 0.18f}, {1.0f, 0.03f, 0.12f, -0.15f}})};
}

}  // namespace marionette
