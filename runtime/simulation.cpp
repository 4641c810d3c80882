#include "runtime/simulation.hpp"

// Static-linking API: lets the hash state live on the stack (no allocation per tick).
#define XXH_STATIC_LINKING_ONLY
#include <xxhash.h>

#include <stdexcept>

#include "runtime/puppet.hpp"

#if defined(__x86_64__) || defined(__i386__)
#include <xmmintrin.h>
#endif

namespace marionette {

namespace {
float clampf(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }

// Stick deflection → speed fraction: radial deadzone, then the response curve.
float stick_response(float deflection, const SimConfig& c) {
    if (deflection <= c.stick_deadzone) return 0.0f;
    float d = (deflection - c.stick_deadzone) / (1.0f - c.stick_deadzone);
    d = clampf(d, 0.0f, 1.0f);
    return (1.0f - c.response_curve) * d + c.response_curve * d * d;
}

void hash_floats(XXH64_state_t* h, const float* v, size_t n) { XXH64_update(h, v, n * sizeof(float)); }
}  // namespace

void set_simulation_float_mode() {
#if defined(__x86_64__) || defined(__i386__)
    _mm_setcsr(_mm_getcsr() | 0x8040u);  // FTZ (bit 15) | DAZ (bit 6)
#elif defined(__aarch64__)
    std::uint64_t fpcr = 0;
    __asm__ volatile("mrs %0, fpcr" : "=r"(fpcr));
    fpcr |= (1ull << 24);  // FZ
    __asm__ volatile("msr fpcr, %0" : : "r"(fpcr));
#endif
}

Simulation::Simulation(const SimConfig& config, const Terrain& terrain) : config_(config), terrain_(terrain) {
    if (config_.tick_rate_hz <= 0) throw std::invalid_argument("tick_rate_hz must be positive");
    const Skeleton skeleton = make_puppet_skeleton(config_);
    if (skeleton.joint_count() > kMaxJoints) throw std::invalid_argument("puppet has too many joints");
    idle_clip_ = make_idle_clip(skeleton, config_);
    walk_clip_ = make_walk_clip(skeleton, config_);
    clip_data_hash_ = hash_clip(idle_clip_) ^ (hash_clip(walk_clip_) * 0x9E3779B97F4A7C15ull);
    // Tick 0: the idle pose at time 0, so even a run of no ticks has a full pose.
    state_.joint_count = skeleton.joint_count();
    const size_t n = static_cast<size_t>(skeleton.joint_count());
    sample_clip(idle_clip_, 0.0, ClipWrap::loop, std::span<quat>(state_.local_rotations.data(), n),
                std::span<vec3>(state_.local_translations.data(), n));
    update_model_space();
}

std::string structural_change(const SimConfig& c, const SimConfig& next) {
    if (next.tick_rate_hz != c.tick_rate_hz) return "simulation.tick_rate_hz";
    const float SimConfig::*const structural[] = {
        &SimConfig::pelvis_height, &SimConfig::hip_width, &SimConfig::thigh_length, &SimConfig::shin_length,
        &SimConfig::ankle_height, &SimConfig::foot_length, &SimConfig::toe_length, &SimConfig::spine_length,
        &SimConfig::neck_length, &SimConfig::head_length, &SimConfig::shoulder_width,
        &SimConfig::upper_arm_length, &SimConfig::forearm_length, &SimConfig::hand_length};
    for (auto field : structural)
        if (next.*field != c.*field) return "puppet (skeleton proportions)";
    if (!(next.terrain == c.terrain)) return "terrain";
    return {};
}

std::string Simulation::retune(const SimConfig& next) {
    std::string key = structural_change(config_, next);
    if (key.empty()) config_ = next;
    return key;
}

void Simulation::update_model_space() {
    const size_t n = static_cast<size_t>(state_.joint_count);
    LocalToModelJob fk{std::span<const int>(skeleton().parents),
                       std::span<const quat>(state_.local_rotations.data(), n),
                       std::span<const vec3>(state_.local_translations.data(), n),
                       std::span<quat>(state_.model_rotations.data(), n),
                       std::span<vec3>(state_.model_positions.data(), n)};
    fk.run();
}

void Simulation::step(const TickInput& input) {
    const SimConfig& c = config_;
    const float dt = 1.0f / static_cast<float>(c.tick_rate_hz);
    PuppetState& s = state_;
    s.input = input;

    // Commanded velocity. Stick up moves away from the camera (−Z), right is +X.
    const float sx = static_cast<float>(input.left_x) / kStickScale;
    const float sy = static_cast<float>(input.left_y) / kStickScale;
    const float deflection = std::sqrt(sx * sx + sy * sy);
    const float speed_fraction = stick_response(deflection > 1.0f ? 1.0f : deflection, c);
    vec2 desired(0.0f);
    if (speed_fraction > 0.0f) {
        const float scale = c.max_speed * speed_fraction / deflection;
        desired = vec2(sx * scale, -sy * scale);
    }

    // Accelerate toward it, limited by the configured acceleration.
    const vec2 dv = desired - s.velocity;
    const float dv_len = std::sqrt(dv.x * dv.x + dv.y * dv.y);
    const float max_dv = c.acceleration * dt;
    s.velocity = dv_len <= max_dv ? desired : s.velocity + dv * (max_dv / dv_len);
    s.root_position.x += s.velocity.x * dt;
    s.root_position.z += s.velocity.y * dt;
    const float speed = std::sqrt(s.velocity.x * s.velocity.x + s.velocity.y * s.velocity.y);

    // Heading turns toward the direction of travel at the configured rate.
    if (speed > 0.05f) {
        const double target = det::atan2(s.velocity.x, s.velocity.y);
        const double diff = det::wrap_angle(target - s.heading);
        const double max_turn = c.turn_rate_deg_s * det::kDegToRad * dt;
        const double turn = diff > max_turn ? max_turn : (diff < -max_turn ? -max_turn : diff);
        s.heading = static_cast<float>(det::wrap_angle(s.heading + turn));
    }

    // Clip playback: the walk cycle advances with distance travelled, idle with time.
    s.locomotion_blend = clampf(speed / c.walk_cycle_speed, 0.0f, 1.0f);
    s.walk_phase += speed * dt / c.stride_length;
    s.walk_phase -= static_cast<float>(static_cast<int>(s.walk_phase));
    s.idle_time += dt;
    if (s.idle_time >= static_cast<float>(idle_clip_.duration())) s.idle_time -= static_cast<float>(idle_clip_.duration());

    const size_t n = static_cast<size_t>(s.joint_count);
    sample_clip(idle_clip_, s.idle_time, ClipWrap::loop, std::span<quat>(s.local_rotations.data(), n),
                std::span<vec3>(s.local_translations.data(), n));
    sample_clip(walk_clip_, s.walk_phase * walk_clip_.duration(), ClipWrap::loop,
                std::span<quat>(walk_rotations_.data(), n), std::span<vec3>(walk_translations_.data(), n));
    for (size_t j = 0; j < n; ++j) {
        s.local_rotations[j] = quat_slerp(s.local_rotations[j], walk_rotations_[j], s.locomotion_blend);
        s.local_translations[j] = lerp(s.local_translations[j], walk_translations_[j], s.locomotion_blend);
    }
    // Place the root: clip height over the ground point, facing the heading.
    s.local_rotations[0] = quat_mul(quat_axis_angle(vec3(0, 1, 0), s.heading), s.local_rotations[0]);
    s.local_translations[0] = vec3(s.root_position.x, s.root_position.y + s.local_translations[0].y, s.root_position.z);

    update_model_space();
    ++s.tick;
}

std::uint64_t hash_state(const PuppetState& s) {
    XXH64_state_t state_memory;
    XXH64_state_t* h = &state_memory;
    XXH64_reset(h, 0);
    XXH64_update(h, &s.tick, sizeof s.tick);
    XXH64_update(h, &s.joint_count, sizeof s.joint_count);
    const std::int16_t axes[4] = {s.input.left_x, s.input.left_y, s.input.right_x, s.input.right_y};
    const std::uint16_t triggers[2] = {s.input.left_trigger, s.input.right_trigger};
    XXH64_update(h, axes, sizeof axes);
    XXH64_update(h, triggers, sizeof triggers);
    XXH64_update(h, &s.input.buttons, sizeof s.input.buttons);
    const float scalars[8] = {s.root_position.x, s.root_position.y, s.root_position.z, s.velocity.x,
                              s.velocity.y, s.heading, s.walk_phase, s.idle_time};
    hash_floats(h, scalars, 8);
    hash_floats(h, &s.locomotion_blend, 1);
    const int n = s.joint_count < 0 ? 0 : (s.joint_count > kMaxJoints ? kMaxJoints : s.joint_count);
    for (int j = 0; j < n; ++j) {
        const size_t i = static_cast<size_t>(j);
        const quat lr = s.local_rotations[i];
        const vec3 lt = s.local_translations[i];
        const quat mr = s.model_rotations[i];
        const vec3 mp = s.model_positions[i];
        const float v[14] = {lr.w, lr.x, lr.y, lr.z, lt.x, lt.y, lt.z, mr.w, mr.x, mr.y, mr.z, mp.x, mp.y, mp.z};
        hash_floats(h, v, 14);
    }
    return XXH64_digest(h);
}

}  // namespace marionette
