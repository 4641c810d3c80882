#pragma once
// Render settings: plain data. They never affect the simulation, so they live in
// their own file (config/render.toml, loaded by app/config/render_config.cpp) and are
// never recorded in input logs.
#include <cstdint>

#include "runtime/math/math.hpp"

namespace marionette::render {

struct CameraSettings {
    float distance_m = 4.2f;      // from the followed point, horizontally
    float height_m = 1.2f;        // above the followed point
    float azimuth_deg = 120.0f;   // world-fixed: 0 looks along +Z from behind the origin
    float fov_deg = 45.0f;        // vertical
    float smoothing_s = 0.25f;    // time constant of the follow; 0 snaps
    float target_height_m = 0.9f; // followed point above the puppet's root
};

struct RenderSettings {
    std::int32_t width = 1280;
    std::int32_t height = 800;
    std::int32_t msaa_samples = 4;
    bool vsync = true;
    bool fullscreen = false;
    CameraSettings camera;
    vec3 sky_colour{0.62f, 0.72f, 0.82f};
    vec3 body_colour{0.86f, 0.70f, 0.52f};
    vec3 left_colour{0.30f, 0.55f, 0.85f};   // left limbs, so the gait reads at a glance
    vec3 right_colour{0.85f, 0.35f, 0.30f};
    vec3 ground_colour{0.55f, 0.60f, 0.50f};
    vec3 box_colour{0.70f, 0.66f, 0.58f};
    vec3 slope_colour{0.62f, 0.58f, 0.66f};
    vec3 overlay_colour{1.0f, 1.0f, 0.2f};
    vec3 hud_colour{1.0f, 1.0f, 1.0f};
    // Debug overlays shown at start; toggled at run time (keys 1-4, H).
    bool show_skeleton = false;
    bool show_feet = false;
    bool show_gait = false;
    bool show_motion_graph = false;
    bool show_hud = true;
};

}  // namespace marionette::render
