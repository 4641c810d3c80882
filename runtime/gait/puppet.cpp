#include "runtime/gait/puppet.hpp"

#include <xxhash.h>

namespace marionette {

namespace {
const vec3 kAxisX(1, 0, 0);
const vec3 kAxisY(0, 1, 0);
const vec3 kAxisZ(0, 0, 1);

void add_joint(Skeleton& s, const char* name, int parent, vec3 offset) {
    s.joint_names.emplace_back(name);
    s.parents.push_back(parent);
    s.rest_offsets.push_back(offset);
}

void add_end_site(Skeleton& s, int parent, vec3 offset) {
    s.end_site_parents.push_back(parent);
    s.end_site_offsets.push_back(offset);
}

Clip empty_clip(const Skeleton& skeleton, const char* name, double rate, int frames) {
    Clip clip;
    clip.name = name;
    clip.skeleton = skeleton;
    clip.frame_rate = rate;
    clip.frame_count = frames;
    const size_t n = static_cast<size_t>(frames) * static_cast<size_t>(skeleton.joint_count());
    clip.rotations.assign(n, quat_identity());
    clip.translations.resize(n);
    for (int f = 0; f < frames; ++f)
        for (int j = 0; j < skeleton.joint_count(); ++j)
            clip.translations[static_cast<size_t>(f * skeleton.joint_count() + j)] =
                skeleton.rest_offsets[static_cast<size_t>(j)];
    clip.animated_translation.assign(static_cast<size_t>(skeleton.joint_count()), false);
    clip.animated_translation[0] = true;
    return clip;
}

quat& rotation_at(Clip& clip, int frame, int joint) {
    return clip.rotations[static_cast<size_t>(frame * clip.joint_count() + joint)];
}
vec3& translation_at(Clip& clip, int frame, int joint) {
    return clip.translations[static_cast<size_t>(frame * clip.joint_count() + joint)];
}
}  // namespace

Skeleton make_puppet_skeleton(const GaitConfig& c) {
    Skeleton s;
    const float spine_segment = c.spine_length / 3.0f;
    add_joint(s, "pelvis", kNoParent, vec3(0, c.pelvis_height, 0));
    add_joint(s, "spine_01", kPelvis, vec3(0, 0.10f, 0));
    add_joint(s, "spine_02", kSpine1, vec3(0, spine_segment, 0));
    add_joint(s, "spine_03", kSpine2, vec3(0, spine_segment, 0));
    add_joint(s, "neck", kSpine3, vec3(0, c.spine_length - 0.10f - spine_segment, 0));
    add_joint(s, "head", kNeck, vec3(0, c.neck_length, 0));
    add_end_site(s, kHead, vec3(0, c.head_length, 0));
    for (int side = 0; side < 2; ++side) {
        const float sign = side == 0 ? 1.0f : -1.0f;  // left is +X
        const bool left = side == 0;
        const int clavicle = s.joint_count();
        add_joint(s, left ? "clavicle_l" : "clavicle_r", kSpine3, vec3(sign * 0.03f, spine_segment * 0.8f, 0.02f));
        add_joint(s, left ? "upperarm_l" : "upperarm_r", clavicle, vec3(sign * (c.shoulder_width * 0.5f - 0.03f), 0, -0.02f));
        add_joint(s, left ? "forearm_l" : "forearm_r", clavicle + 1, vec3(0, -c.upper_arm_length, 0));
        add_joint(s, left ? "hand_l" : "hand_r", clavicle + 2, vec3(0, -c.forearm_length, 0));
        add_end_site(s, clavicle + 3, vec3(0, -c.hand_length, 0));
    }
    for (int side = 0; side < 2; ++side) {
        const float sign = side == 0 ? 1.0f : -1.0f;
        const bool left = side == 0;
        const int thigh = s.joint_count();
        add_joint(s, left ? "thigh_l" : "thigh_r", kPelvis, vec3(sign * c.hip_width * 0.5f, 0, 0));
        add_joint(s, left ? "shin_l" : "shin_r", thigh, vec3(0, -c.thigh_length, 0));
        add_joint(s, left ? "foot_l" : "foot_r", thigh + 1, vec3(0, -c.shin_length, 0));
        add_joint(s, left ? "toe_l" : "toe_r", thigh + 2, vec3(0, -c.ankle_height, c.foot_length));
        add_end_site(s, thigh + 3, vec3(0, 0, c.toe_length));
    }
    return s;
}

Clip make_idle_clip(const Skeleton& skeleton, const GaitConfig&) {
    constexpr double kRate = 30.0;
    constexpr int kFrames = 121;  // one 4 s breath, last frame equals the first
    Clip clip = empty_clip(skeleton, "idle", kRate, kFrames);
    for (int f = 0; f < kFrames; ++f) {
        const double phase = det::kTwoPi * f / (kFrames - 1);
        const double breath = det::sin(phase);
        translation_at(clip, f, kPelvis).y += static_cast<float>(0.004 * breath);
        rotation_at(clip, f, kSpine2) = quat_axis_angle(kAxisX, -0.015 * breath);
        rotation_at(clip, f, kSpine3) = quat_axis_angle(kAxisX, -0.02 * breath);
        rotation_at(clip, f, kHead) = quat_axis_angle(kAxisX, 0.02 * breath);
        // Arms hang slightly away from the body.
        rotation_at(clip, f, kUpperArmL) = quat_axis_angle(kAxisZ, 0.08 + 0.01 * breath);
        rotation_at(clip, f, kUpperArmR) = quat_axis_angle(kAxisZ, -0.08 - 0.01 * breath);
        rotation_at(clip, f, kForearmL) = quat_axis_angle(kAxisX, -0.15);
        rotation_at(clip, f, kForearmR) = quat_axis_angle(kAxisX, -0.15);
    }
    return clip;
}

Clip make_walk_clip(const Skeleton& skeleton, const GaitConfig&) {
    constexpr double kRate = 60.0;
    constexpr int kFrames = 61;  // one full cycle (two steps); last frame equals the first
    Clip clip = empty_clip(skeleton, "walk", kRate, kFrames);
    for (int f = 0; f < kFrames; ++f) {
        const double phase = det::kTwoPi * f / (kFrames - 1);
        double s = 0.0, c = 0.0;
        det::sin_cos(phase, s, c);
        // Hip flexion swings the legs in antiphase (positive X rotation lifts the
        // leg forward toward +Z); the knee bends during each leg's swing.
        const double hip_amplitude = 0.42;
        const double left_knee = 0.35 + 0.35 * (s > 0 ? s : 0.0);
        const double right_knee = 0.35 + 0.35 * (s < 0 ? -s : 0.0);
        rotation_at(clip, f, kThighL) = quat_axis_angle(kAxisX, -hip_amplitude * s);
        rotation_at(clip, f, kThighR) = quat_axis_angle(kAxisX, hip_amplitude * s);
        rotation_at(clip, f, kShinL) = quat_axis_angle(kAxisX, left_knee * 0.5 + 0.05);
        rotation_at(clip, f, kShinR) = quat_axis_angle(kAxisX, right_knee * 0.5 + 0.05);
        rotation_at(clip, f, kFootL) = quat_axis_angle(kAxisX, -0.15 * c);
        rotation_at(clip, f, kFootR) = quat_axis_angle(kAxisX, 0.15 * c);
        // Arms counter-swing, spine twists against the pelvis, pelvis bobs twice a cycle.
        rotation_at(clip, f, kUpperArmL) = quat_mul(quat_axis_angle(kAxisZ, 0.1), quat_axis_angle(kAxisX, 0.35 * s));
        rotation_at(clip, f, kUpperArmR) = quat_mul(quat_axis_angle(kAxisZ, -0.1), quat_axis_angle(kAxisX, -0.35 * s));
        rotation_at(clip, f, kForearmL) = quat_axis_angle(kAxisX, -0.35 - 0.15 * (s > 0 ? s : 0.0));
        rotation_at(clip, f, kForearmR) = quat_axis_angle(kAxisX, -0.35 - 0.15 * (s < 0 ? -s : 0.0));
        rotation_at(clip, f, kPelvis) = quat_mul(quat_axis_angle(kAxisY, 0.08 * s), quat_axis_angle(kAxisX, 0.05));
        rotation_at(clip, f, kSpine2) = quat_axis_angle(kAxisY, -0.12 * s);
        translation_at(clip, f, kPelvis).y -= static_cast<float>(0.03 + 0.02 * s * s);
    }
    return clip;
}

std::uint64_t hash_clip(const Clip& clip) {
    XXH64_state_t* state = XXH64_createState();
    XXH64_reset(state, 0x6d617269u);
    for (size_t j = 0; j < clip.skeleton.joint_names.size(); ++j) {
        const std::string& name = clip.skeleton.joint_names[j];
        XXH64_update(state, name.data(), name.size() + 1);  // include the terminator as separator
        const int parent = clip.skeleton.parents[j];
        XXH64_update(state, &parent, sizeof parent);
        const vec3 o = clip.skeleton.rest_offsets[j];
        const float offset[3] = {o.x, o.y, o.z};
        XXH64_update(state, offset, sizeof offset);
    }
    XXH64_update(state, &clip.frame_rate, sizeof clip.frame_rate);
    XXH64_update(state, &clip.frame_count, sizeof clip.frame_count);
    for (const quat& q : clip.rotations) {
        const float v[4] = {q.w, q.x, q.y, q.z};
        XXH64_update(state, v, sizeof v);
    }
    for (const vec3& t : clip.translations) {
        const float v[3] = {t.x, t.y, t.z};
        XXH64_update(state, v, sizeof v);
    }
    const std::uint64_t h = XXH64_digest(state);
    XXH64_freeState(state);
    return h;
}

}  // namespace marionette
