#pragma once
// Pose buffers filled with values no job writes (not unit quaternions, points
// far off), so a job test can see that a refused run() touched nothing.
#include <algorithm>
#include <cstddef>
#include <vector>

#include "runtime/anim/pose_spans.hpp"

namespace marionette::test {

inline const quat kSentinelRotation{9.0f, -9.0f, 9.0f, -9.0f};
inline const vec3 kSentinelPosition{-999.0f, 999.0f, -999.0f};

struct SentinelPose {
    std::vector<quat> local_rotations, model_rotations;
    std::vector<vec3> local_translations, model_positions;

    explicit SentinelPose(std::size_t joints)
        : local_rotations(joints, kSentinelRotation),
          model_rotations(joints, kSentinelRotation),
          local_translations(joints, kSentinelPosition),
          model_positions(joints, kSentinelPosition) {}

    PoseSpans spans() { return {local_rotations, local_translations, model_rotations, model_positions}; }
    LocalPoseOutput local() { return {local_rotations, local_translations}; }
    ModelPoseOutput model() { return {model_rotations, model_positions}; }

    bool untouched() const {
        const auto is_rotation = [](const quat& q) { return q == kSentinelRotation; };
        const auto is_position = [](const vec3& p) { return p == kSentinelPosition; };
        return std::all_of(local_rotations.begin(), local_rotations.end(), is_rotation) &&
               std::all_of(model_rotations.begin(), model_rotations.end(), is_rotation) &&
               std::all_of(local_translations.begin(), local_translations.end(), is_position) &&
               std::all_of(model_positions.begin(), model_positions.end(), is_position);
    }
};

}  // namespace marionette::test
