#pragma once
// Skeleton and pose as flat arrays (structure of arrays, one entry per joint),
// joints in topological order so a single forward pass does forward kinematics.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/anim/fk_schedule.hpp"
#include "runtime/anim/pose_spans.hpp"
#include "runtime/errors/outcome.hpp"
#include "runtime/math/math.hpp"

namespace marionette {

struct Skeleton {
    std::vector<std::string> joint_names;
    std::vector<int> parents;             // parents[i] < i, or kNoParent for roots
    std::vector<vec3> rest_offsets;       // joint position in its parent's frame at rest
    // Offsets of the BVH "End Site"s (or ASF bone ends of leaves), kept so an export
    // can draw leaf bones; not joints (no rotation, no name).
    std::vector<int> end_site_parents;
    std::vector<vec3> end_site_offsets;

    int joint_count() const { return static_cast<int>(parents.size()); }
    // Index of the joint with this exact name, or -1.
    int find(std::string_view name) const;
};

// Ok when the skeleton is well formed, otherwise what is wrong (sizes differ, a
// parent index not before its child, duplicate or empty names).
Outcome validate_skeleton(const Skeleton& skeleton);

// A pose is the local transform of every joint: rotation relative to the parent
// and translation in the parent's frame (the rest offset, unless the source
// animates it: a BVH position channel, the root's motion).
struct Pose {
    std::vector<quat> local_rotations;
    std::vector<vec3> local_translations;
};

Pose rest_pose(const Skeleton& skeleton);

// Forward kinematics: local transforms → model space, one pass in joint order.
// A job (runtime/anim/pose_spans.hpp): validate() checks the sizes (the model
// spans may be longer than the skeleton) and the topological order.
// With a schedule built from the same parents (runtime/anim/fk_schedule.hpp,
// built once per skeleton) it solves two joints per vector where the CPU has
// AVX2; validate() then checks that the schedule matches the parents instead.
// The bits are the same either way.
struct LocalToModelJob {
    std::span<const int> parents;
    LocalPoseInput input;
    ModelPoseOutput output;
    const FkSchedule* schedule = nullptr;

    bool validate() const;
    [[nodiscard]] bool run() const;
};

}  // namespace marionette
