#include "runtime/anim/clip.hpp"

#include <cmath>

namespace marionette {

Outcome validate_clip(const Clip& clip) {
    if (Outcome skeleton = validate_skeleton(clip.skeleton); !skeleton.ok()) return skeleton;
    if (!(clip.frame_rate > 0.0) || !std::isfinite(clip.frame_rate)) return Outcome::failure("frame rate must be positive");
    if (clip.frame_count < 1) return Outcome::failure("clip has no frames");
    const size_t expected = static_cast<size_t>(clip.frame_count) * static_cast<size_t>(clip.joint_count());
    if (clip.rotations.size() != expected || clip.translations.size() != expected)
        return Outcome::failure("pose arrays do not hold frame_count × joint_count entries");
    if (clip.animated_translation.size() != static_cast<size_t>(clip.joint_count()))
        return Outcome::failure("animated_translation must have one flag per joint");
    return Outcome::success();
}

void sample_clip(const Clip& clip, double time_seconds, ClipWrap wrap, std::span<quat> out_rotations,
                 std::span<vec3> out_translations) {
    const size_t joints = static_cast<size_t>(clip.joint_count());
    const int last = clip.frame_count - 1;
    double frame_position = time_seconds * clip.frame_rate;
    if (!std::isfinite(frame_position)) frame_position = 0.0;
    if (wrap == ClipWrap::loop && last > 0) {
        frame_position = std::fmod(frame_position, static_cast<double>(last));
        if (frame_position < 0.0) frame_position += last;
    }
    if (frame_position <= 0.0) frame_position = 0.0;
    if (frame_position >= last) frame_position = last;
    const int f0 = static_cast<int>(frame_position);
    const int f1 = f0 < last ? f0 + 1 : f0;
    const float t = static_cast<float>(frame_position - f0);
    const quat* r0 = clip.frame_rotations(f0);
    const quat* r1 = clip.frame_rotations(f1);
    const vec3* p0 = clip.frame_translations(f0);
    const vec3* p1 = clip.frame_translations(f1);
    for (size_t j = 0; j < joints; ++j) {
        out_rotations[j] = quat_slerp(r0[j], r1[j], t);
        out_translations[j] = lerp(p0[j], p1[j], t);
    }
}

Clip resample_clip(const Clip& clip, double new_rate) {
    Clip out;
    out.name = clip.name;
    out.skeleton = clip.skeleton;
    out.animated_translation = clip.animated_translation;
    out.length_unit = clip.length_unit;
    out.frame_rate = new_rate;
    const double duration = clip.duration();
    out.frame_count = static_cast<int>(std::floor(duration * new_rate + 1e-9)) + 1;
    const size_t joints = static_cast<size_t>(clip.joint_count());
    out.rotations.resize(static_cast<size_t>(out.frame_count) * joints);
    out.translations.resize(out.rotations.size());
    for (int f = 0; f < out.frame_count; ++f) {
        const double t = (f == out.frame_count - 1 && out.frame_count > 1) ? duration : f / new_rate;
        sample_clip(clip, t, ClipWrap::clamp,
                    std::span<quat>(out.rotations.data() + static_cast<size_t>(f) * joints, joints),
                    std::span<vec3>(out.translations.data() + static_cast<size_t>(f) * joints, joints));
    }
    return out;
}

}  // namespace marionette
