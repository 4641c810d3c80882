#pragma once
// Internals shared by retarget.cpp and contacts.cpp (not for other folders).
#include "retarget/directions.hpp"
#include "retarget/pose_space.hpp"
#include "retarget/retarget.hpp"

#include <cmath>
#include <cstddef>

namespace marionette::retarget::detail {

// Source positions → the puppet's world: the ground to y = 0, turned so the
// source's rest facing is +Z, scaled by leg length.
struct SourceToPuppet {
    quat yaw = quat_identity();
    float scale = 1.0f;
    float floor = 0.0f;
    vec3 apply(vec3 p) const { return scale * quat_rotate(yaw, p - vec3(0.0f, floor, 0.0f)); }
};

// Index of joint j of frame `frame` in a frame-major array of `joints` per frame.
inline std::size_t at(int frame, int joints, int j) {
    return static_cast<std::size_t>(frame) * static_cast<std::size_t>(joints) + static_cast<std::size_t>(j);
}

using retarget::unit;  // retarget/directions.hpp

inline vec3 point_of(const ModelFrames& m, int f, SourcePoint s) { return lerp(m.position(f, s.a), m.position(f, s.b), s.t); }

// Detects the source's foot contacts into result.contact_kind, pins them on the
// puppet with two-bone IK (unless options.fix_contacts is false) and measures
// how far pinned points drift (result.contacts).
void fix_contacts(const ModelFrames& source, const HumanoidChains& chains, const SourceToPuppet& to_puppet,
                  const RetargetOptions& options, float puppet_leg, RetargetResult& result);

}  // namespace marionette::retarget::detail
