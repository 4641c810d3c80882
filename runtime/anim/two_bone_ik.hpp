#pragma once
// Analytic two-bone IK (hip–knee–ankle, shoulder–elbow–wrist) as a job
// (runtime/anim/pose_spans.hpp): parameters in, result out, no allocation, no
// hidden state. The law of cosines gives
// the bend; the rotations come from cross and dot products (half-angle
// identities), so there is not one trig call and the bits are the same on every
// platform.
//
// Segment frames (world space) follow the puppet's convention: a segment's
// local −Y runs along the bone toward its child, local +X is the hinge axis,
// +Z = X × Y. The joint bends toward the pole: the mid joint (knee, elbow) lies in
// the plane of root, target and pole direction, on the pole's side. For a knee
// (pole ahead) a straight leg then has the rest frame; an elbow (pole behind)
// sets hinge_sign = −1 so a straight arm has it too.
#include <span>

#include "runtime/math/math.hpp"

namespace marionette {

struct TwoBoneIkResult {
    vec3 mid{0.0f};                      // knee / elbow, world
    vec3 end{0.0f};                      // where the end joint actually is
    vec3 hinge_axis{1.0f, 0.0f, 0.0f};   // unit, shared by both segment frames
    quat upper_rotation{1.0f, 0.0f, 0.0f, 0.0f};  // world frame of the upper segment
    quat lower_rotation{1.0f, 0.0f, 0.0f, 0.0f};  // world frame of the lower segment
    float reach = 0.0f;                  // distance root → end after softening and clamping
    bool reached = false;                // end == target (within 0.1 mm)
};

struct TwoBoneIkJob {
    vec3 root{0.0f};                    // hip / shoulder, world
    vec3 target{0.0f};                  // where the end joint (ankle / wrist) should go
    vec3 pole{0.0f, 0.0f, 1.0f};        // direction the mid joint should point (knees forward, elbows back)
    float upper_length = 0.0f;          // root to mid
    float lower_length = 0.0f;          // mid to end
    // Soft reach: past soft_reach_start × (upper + lower) the reach approaches full
    // extension asymptotically instead of snapping straight (rational ease, no exp).
    float soft_reach_start = 0.98f;
    // Closest the end may come to the root: |upper − lower| plus this fraction of
    // (upper + lower), so a fully folded limb still has a defined bend.
    float min_reach_margin = 1e-4f;
    float hinge_sign = 1.0f;            // +1: frame +Z toward the pole; −1: away from it
    TwoBoneIkResult* result = nullptr;  // out

    // False when there is no result to write, a length is not positive or a
    // value is not finite.
    bool validate() const;
    [[nodiscard]] bool run() const;
};

// The solve run() performs once validate() passed, without the check: for a
// job (GaitPoseJob) whose own validate() already covered these inputs (positive,
// finite lengths, finite root, target and pole), so a tick validates once.
// Inputs validate() would refuse give unspecified values (no crash, no UB).
TwoBoneIkResult solve_two_bone_ik(const TwoBoneIkJob& job);

// Rotation whose columns are the given orthonormal axes (right-handed), via
// Shepperd's method: sqrt only.
quat quat_from_axes(vec3 x_axis, vec3 y_axis, vec3 z_axis);

// Shortest rotation taking unit vector `from` onto unit vector `to`, from the
// half-angle identity q = normalize(1 + from·to, from × to); antiparallel vectors
// turn about any perpendicular axis.
quat quat_from_to(vec3 from, vec3 to);

}  // namespace marionette

namespace marionette {

// Up to four solves at once (the legs, the arms), one per lane of a 4-lane
// vector (SSE on x86-64, NEON on AArch64, GCC/Clang vector extensions
// elsewhere). Each lane performs solve_two_bone_ik's operations in its order,
// as separate IEEE operations, and its branches become lane selects of values
// computed the same way: every result has the same bits as solve_two_bone_ik's
// for that job (tests/runtime/anim/test_two_bone_ik_job.cpp compares them on
// random jobs). Like solve_two_bone_ik it trusts its inputs (validate() each
// job first); jobs.size() == results.size() <= 4.
void solve_two_bone_ik_lanes(std::span<const TwoBoneIkJob> jobs, std::span<TwoBoneIkResult> results);

// The jobs above as a job: validate() checks the counts and every job.
struct TwoBoneIkLanesJob {
    std::span<const TwoBoneIkJob> jobs;  // 1 to 4 jobs; their result pointers are not used
    std::span<TwoBoneIkResult> results;  // out: one per job
    bool validate() const;
    [[nodiscard]] bool run() const;
};

}  // namespace marionette
