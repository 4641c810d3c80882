#pragma once
// The default humanoid puppet (22 joints) built from configured proportions, and
// the clips the project authors procedurally for it, so the default demo needs no
// external data.
#include <cstdint>

#include "runtime/anim/clip.hpp"
#include "runtime/gait/gait_config.hpp"

namespace marionette {

// Joint indices of the default puppet, in topological order.
enum PuppetJoint : int {
    kPelvis, kSpine1, kSpine2, kSpine3, kNeck, kHead,
    kClavicleL, kUpperArmL, kForearmL, kHandL,
    kClavicleR, kUpperArmR, kForearmR, kHandR,
    kThighL, kShinL, kFootL, kToeL,
    kThighR, kShinR, kFootR, kToeR,
    kPuppetJointCount
};

// +Y up; the puppet faces +Z at heading 0 and its left side is +X.
Skeleton make_puppet_skeleton(const GaitConfig& config);

// Standing pose with a slow breathing motion, one breath over the clip, looping.
Clip make_idle_clip(const Skeleton& skeleton, const GaitConfig& config);

// One walk cycle in place (root translation carries only the vertical bob), looping,
// authored with sinusoidal joint curves; it advances stride_length per cycle.
Clip make_walk_clip(const Skeleton& skeleton, const GaitConfig& config);

// 64-bit hash of a clip's skeleton and sample data: logs record it so a replay
// can tell it is animating the same data.
std::uint64_t hash_clip(const Clip& clip);

}  // namespace marionette
