#include "render_es/camera.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>

namespace marionette::render {

void follow(FollowCamera& camera, vec3 puppet_root, float dt_s, const CameraSettings& s) {
    const vec3 goal = puppet_root + vec3(0.0f, s.target_height_m, 0.0f);
    if (!camera.placed || s.smoothing_s <= 0.0f) {
        camera.target = goal;
        camera.placed = true;
        return;
    }
    // Rendering is not the tick: std::exp is fine here.
    const float k = 1.0f - std::exp(-(dt_s > 0.0f ? dt_s : 0.0f) / s.smoothing_s);
    camera.target += (goal - camera.target) * k;
}

vec3 camera_eye(const FollowCamera& camera, const CameraSettings& s) {
    const float azimuth = glm::radians(s.azimuth_deg);
    return camera.target + vec3(-std::sin(azimuth) * s.distance_m, s.height_m, -std::cos(azimuth) * s.distance_m);
}

glm::mat4 camera_view_projection(const FollowCamera& camera, const CameraSettings& s, float aspect) {
    const glm::mat4 view = glm::lookAt(camera_eye(camera, s), camera.target, vec3(0, 1, 0));
    const glm::mat4 projection = glm::perspective(glm::radians(s.fov_deg), aspect, 0.05f, 200.0f);
    return projection * view;
}

}  // namespace marionette::render
