#pragma once
// Model-space poses of whole clips, for the offline retargeter: every frame's
// joints (and end sites, after the joints) in world space.
#include <vector>

#include "runtime/anim/clip.hpp"

namespace marionette::retarget {

// Rest pose in model space: `rotations` per joint, `points` per joint then per
// end site.
void rest_model_pose(const Skeleton& skeleton, std::vector<quat>& rotations, std::vector<vec3>& points);

struct ModelFrames {
    int points = 0;  // joints + end sites
    int joints = 0;
    std::vector<quat> rotations;  // frame-major, joints only
    std::vector<vec3> positions;  // frame-major, joints then end sites
    vec3 position(int frame, int point) const {
        return positions[static_cast<size_t>(frame) * static_cast<size_t>(points) + static_cast<size_t>(point)];
    }
    quat rotation(int frame, int joint) const {
        return rotations[static_cast<size_t>(frame) * static_cast<size_t>(joints) + static_cast<size_t>(joint)];
    }
};

// Forward kinematics of every frame (LocalToModelJob), end sites included.
ModelFrames model_frames(const Clip& clip);

}  // namespace marionette::retarget
