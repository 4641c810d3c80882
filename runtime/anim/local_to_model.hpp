#pragma once
// The forward-kinematics kernels behind LocalToModelJob (skeleton.hpp). All
// take inputs LocalToModelJob::validate() accepted and write the same bits: the
// vector and pair kernels keep the scalar one's operations in the scalar one's
// order (see local_to_model.cpp), so run() uses them and the tests compare them.
#include <span>

#include "runtime/anim/pose_spans.hpp"

namespace marionette {
class FkSchedule;
}

namespace marionette::fk {

// One joint at a time, quat_mul/quat_rotate on floats: the reference.
void local_to_model_scalar(std::span<const int> parents, const LocalPoseInput& input, const ModelPoseOutput& output);

// One joint per 4-lane vector (SSE2 on x86-64, NEON on AArch64, GCC/Clang vector
// extensions elsewhere): the quaternion's components are the lanes.
void local_to_model_vector(std::span<const int> parents, const LocalPoseInput& input, const ModelPoseOutput& output);

// Two joints per 256-bit vector in the schedule's order (fk_schedule.hpp), the
// same bits again (local_to_model_pairs.cpp): where pairs_kernel_available()
// (x86-64 with AVX2, checked once at run time); otherwise it runs
// local_to_model_vector over the schedule's parents. The schedule must be
// valid and cover the spans (LocalToModelJob::validate() checks both).
void local_to_model_pairs(const FkSchedule& schedule, const LocalPoseInput& input, const ModelPoseOutput& output);
bool pairs_kernel_available();

// What a job that runs FK uses, so each does it one way: the order check (the
// schedule built from these parents, or without one the parents' own order)
// and the kernel (the pair kernel with a schedule, else the vector kernel).
bool order_valid(std::span<const int> parents, const FkSchedule* schedule);
void local_to_model(std::span<const int> parents, const FkSchedule* schedule, const LocalPoseInput& input,
                    const ModelPoseOutput& output);

}  // namespace marionette::fk
