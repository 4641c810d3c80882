#include "render_es/interpolate.hpp"

namespace marionette::render {

namespace {
// previous + t·(current − previous) for any t (t > 1 extrapolates).
void blend_state(const PuppetState& previous, const PuppetState& current, float t, PuppetState& out) {
    out = current;
    out.root_position = lerp(previous.root_position, current.root_position, t);
    out.velocity = previous.velocity + (current.velocity - previous.velocity) * t;
    constexpr float pi = static_cast<float>(det::kPi);
    float turn = current.heading - previous.heading;
    while (turn > pi) turn -= 2.0f * pi;
    while (turn < -pi) turn += 2.0f * pi;
    out.heading = previous.heading + turn * t;
    const int joints = current.joint_count < previous.joint_count ? current.joint_count : previous.joint_count;
    for (int j = 0; j < joints; ++j) {
        const size_t i = static_cast<size_t>(j);
        out.model_positions[i] = lerp(previous.model_positions[i], current.model_positions[i], t);
        out.model_rotations[i] = quat_slerp(previous.model_rotations[i], current.model_rotations[i], t);
        out.local_translations[i] = lerp(previous.local_translations[i], current.local_translations[i], t);
        out.local_rotations[i] = quat_slerp(previous.local_rotations[i], current.local_rotations[i], t);
    }
}
}  // namespace

void interpolate_state(const PuppetState& previous, const PuppetState& current, float alpha, PuppetState& out) {
    blend_state(previous, current, alpha < 0.0f ? 0.0f : (alpha > 1.0f ? 1.0f : alpha), out);
}

void extrapolate_state(const PuppetState& previous, const PuppetState& current, float ahead, PuppetState& out) {
    blend_state(previous, current, 1.0f + (ahead < 0.0f ? 0.0f : (ahead > 1.0f ? 1.0f : ahead)), out);
}

}  // namespace marionette::render
