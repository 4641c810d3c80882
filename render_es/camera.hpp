#pragma once
// A camera that follows the puppet smoothly: the followed point eases toward the
// puppet's root (exponential smoothing with a time constant), the camera sits at
// a world-fixed azimuth, distance and height from it, so walking reads as motion
// across the terrain rather than the world spinning.
#include <glm/mat4x4.hpp>

#include "render_es/settings.hpp"

namespace marionette::render {

struct FollowCamera {
    vec3 target{0.0f};
    bool placed = false;   // false: the next follow() snaps to the puppet
};

// Moves the followed point toward `puppet_root` over dt_s seconds.
void follow(FollowCamera& camera, vec3 puppet_root, float dt_s, const CameraSettings& settings);

vec3 camera_eye(const FollowCamera& camera, const CameraSettings& settings);
glm::mat4 camera_view_projection(const FollowCamera& camera, const CameraSettings& settings, float aspect);

}  // namespace marionette::render
