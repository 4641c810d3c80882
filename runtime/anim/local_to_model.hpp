#pragma once
// The two forward-kinematics kernels behind LocalToModelJob (skeleton.hpp).
// Both take inputs LocalToModelJob::validate() accepted and write the same bits:
// the vector kernel keeps the scalar one's operations in the scalar one's order
// (see local_to_model.cpp), so run() uses it and the tests compare the two.
#include <span>

#include "runtime/anim/pose_spans.hpp"

namespace marionette::fk {

// One joint at a time, quat_mul/quat_rotate on floats: the reference.
void local_to_model_scalar(std::span<const int> parents, const LocalPoseInput& input, const ModelPoseOutput& output);

// One joint per 4-lane vector (SSE2 on x86-64, NEON on AArch64, GCC/Clang vector
// extensions elsewhere): the quaternion's components are the lanes.
void local_to_model_vector(std::span<const int> parents, const LocalPoseInput& input, const ModelPoseOutput& output);

}  // namespace marionette::fk
