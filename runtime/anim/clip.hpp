#pragma once
// A clip: a skeleton plus poses sampled at a fixed rate, frame-major flat arrays.
#include <string>
#include <vector>

#include "runtime/anim/skeleton.hpp"

namespace marionette {

struct Clip {
    std::string name;              // usually the file name without extension
    Skeleton skeleton;
    double frame_rate = 30.0;      // frames per second
    int frame_count = 0;
    // Frame f, joint j lives at [f * joint_count + j].
    std::vector<quat> rotations;
    std::vector<vec3> translations;
    // Joints whose translation is animated (BVH position channels, ASF root);
    // an exporter writes position channels for exactly these.
    std::vector<bool> animated_translation;
    // Length unit of the source relative to the numbers stored (ASF `:units length`);
    // 1 for BVH. Data stays in the file's units.
    double length_unit = 1.0;

    int joint_count() const { return skeleton.joint_count(); }
    double duration() const { return frame_count > 1 ? (frame_count - 1) / frame_rate : 0.0; }
    const quat* frame_rotations(int frame) const {
        return rotations.data() + static_cast<size_t>(frame) * static_cast<size_t>(joint_count());
    }
    const vec3* frame_translations(int frame) const {
        return translations.data() + static_cast<size_t>(frame) * static_cast<size_t>(joint_count());
    }
};

// Ok when sizes and the skeleton are consistent, otherwise what is wrong.
Outcome validate_clip(const Clip& clip);

enum class ClipWrap { clamp, loop };

// Pose at an arbitrary time: slerp between the two neighbouring frames' rotations
// and lerp between their translations. `out` must already be sized to the joint
// count (no allocation here).
void sample_clip(const Clip& clip, double time_seconds, ClipWrap wrap, std::span<quat> out_rotations,
                 std::span<vec3> out_translations);

// The same clip sampled at a new rate (e.g. the tick rate); the duration is kept
// and the last frame is the original last frame.
Clip resample_clip(const Clip& clip, double new_rate);

}  // namespace marionette
