#pragma once
// The spans every job reads and writes a pose through, declared once: one entry
// per joint, joints in topological order (parents before children).
//
// The job contract (ozz-animation's): a job is a struct of input spans,
// parameters and output spans with `bool validate() const` and
// `bool run() const`. run() calls validate() first and, when the inputs are
// wrong, returns false without touching any output; it never allocates and
// never throws, so the tick can run it.
#include <cassert>
#include <cstddef>
#include <span>

#include "runtime/math/math.hpp"

namespace marionette {

inline constexpr int kNoParent = -1;

// Local transforms, read only: rotation relative to the parent and translation
// in the parent's frame.
struct LocalPoseInput {
    std::span<const quat> rotations;
    std::span<const vec3> translations;
};

// Local transforms, written (a sampled or blended pose).
struct LocalPoseOutput {
    std::span<quat> rotations;
    std::span<vec3> translations;
};

// Model-space transforms, written by forward kinematics.
struct ModelPoseOutput {
    std::span<quat> rotations;
    std::span<vec3> positions;
};

// Local and model transforms of one pose, both read and written (a job that
// edits the locals and keeps the model space in step with them).
struct PoseSpans {
    std::span<quat> local_rotations;
    std::span<vec3> local_translations;
    std::span<quat> model_rotations;
    std::span<vec3> model_positions;

    LocalPoseInput local() const { return {local_rotations, local_translations}; }
    ModelPoseOutput model() const { return {model_rotations, model_positions}; }
    // True when every span holds exactly `joints` entries.
    bool has_joints(std::size_t joints) const {
        return local_rotations.size() == joints && local_translations.size() == joints &&
               model_rotations.size() == joints && model_positions.size() == joints;
    }
};

// True when every parent index is kNoParent or an earlier joint: the order
// one forward pass needs.
// One unsigned comparison per joint (every job's validate() runs it): with
// kNoParent = -1, p + 1 wraps -1 to 0 and any other negative p to a huge
// value, so p + 1 <= i exactly when p is kNoParent or in [0, i).
inline bool parents_in_topological_order(std::span<const int> parents) {
    static_assert(kNoParent == -1);
    bool ok = true;
    for (std::size_t i = 0; i < parents.size(); ++i)
        ok &= static_cast<std::size_t>(static_cast<unsigned>(parents[i]) + 1u) <= i;
    return ok;
}

// For callers that built a job's inputs themselves (spans sized from the same
// skeleton), so a false run() can only be a bug: stop there in debug builds. In
// release the outputs keep their previous values (a failed job touches
// nothing); the real-time path never throws.
inline void expect_job_ran([[maybe_unused]] bool ran) { assert(ran && "a job's inputs failed its validate()"); }

}  // namespace marionette
