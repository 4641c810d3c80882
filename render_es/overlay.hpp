#pragma once
// What the debug overlays draw, as plain fixed-size data the simulation side
// fills (the gait and the motion graph) and the render thread reads. No
// pointers, no heap: it is copied between threads with the state.
#include <array>
#include <cstdint>

#include "runtime/math/math.hpp"

namespace marionette::render {

inline constexpr int kOverlayMaxFeet = 4;
inline constexpr int kOverlaySplinePoints = 32;
inline constexpr int kOverlayNameLength = 32;

struct FootOverlay {
    vec3 position{0.0f};                                 // where the foot is now
    vec3 target{0.0f};                                   // where the gait plans to put it
    bool in_contact = false;
    std::int32_t spline_points = 0;                      // swing spline samples, 0: none
    std::array<vec3, kOverlaySplinePoints> spline{};
};

struct MotionGraphOverlay {
    bool valid = false;
    std::array<char, kOverlayNameLength> current_clip{};      // NUL-terminated
    std::array<char, kOverlayNameLength> next_transition{};   // NUL-terminated, empty: none
    float transition_progress = 0.0f;                          // 0..1
};

struct DebugOverlay {
    std::int32_t foot_count = 0;
    std::array<FootOverlay, kOverlayMaxFeet> feet{};
    MotionGraphOverlay motion_graph;
};

struct OverlayToggles {
    bool skeleton = false;
    bool feet = false;
    bool gait = false;
    bool motion_graph = false;
    bool hud = true;
};

}  // namespace marionette::render
