#pragma once
// The spline-IK gait (docs/gait.md): stick → velocity, step planning on the
// terrain, swing paths fitted from blended walk/run Hermite prototypes, stance
// feet pinned, pelvis from the feet, two-bone IK for legs and arms.
//
// Two steps, so the pose source can be swapped (the simulation offers
// procedural gait / motion graph / graph + procedural foot placement):
//   update_gait()  advances the plan: GaitState(k) + input → GaitState(k+1)
//   GaitPoseJob    turns a GaitState into local and model joint transforms.
// Both are pure functions of their arguments and never allocate.
#include <array>
#include <cstdint>
#include <span>

#include "runtime/anim/fk_schedule.hpp"
#include "runtime/anim/pose_spans.hpp"
#include "runtime/math/hermite_spline.hpp"
#include "runtime/gait/gait_config.hpp"
#include "runtime/ground/terrain.hpp"

namespace marionette {

inline constexpr int kSwingPathKeys = 20;

enum class GaitMode : std::int32_t { idle = 0, stepping = 1, stopping = 2 };

struct FootState {
    vec3 ankle{0.0f};                         // where the ankle is now (IK target), world
    quat rotation{1.0f, 0.0f, 0.0f, 0.0f};    // foot frame now: +Y sole normal, +Z toes
    float ground = 0.0f;                      // ground height the foot stands on / is heading for
    std::int32_t swinging = 0;                // 0 stance (pinned), 1 swing
    // The current swing (meaningful while swinging).
    vec3 start{0.0f};
    quat start_rotation{1.0f, 0.0f, 0.0f, 0.0f};
    float start_ground = 0.0f;
    vec3 target{0.0f};
    quat target_rotation{1.0f, 0.0f, 0.0f, 0.0f};
    float target_ground = 0.0f;
    float progress = 0.0f;                    // 0 → 1 over the swing
    float fraction = 0.0f;                    // of the step's horizontal distance covered
    float lift_phase = 0.0f;                  // the foot's cycle phase at lift-off (progress 0)
    float timed_rate = 0.0f;                  // > 0: progress per second (stop transition), else phase-driven
    float lift_scale = 1.0f;                  // small steps lift less
    std::int32_t turn_order = 0;              // the foot turns mid-step (0), over its first (-1) or second (1) half (beside a wall)
    float reach_carry = 0.0f;                 // mid-swing reach allowance a re-aimed swing took over (docs/gait.md, Pelvis)
    std::int32_t replanned = 0;               // times this swing re-aimed (at most 3)
    float planned_speed = 0.0f;               // the command the target was planned for
    float planned_heading = 0.0f;
    // A re-aimed swing carries the foot's velocity (sideways, forward and up)
    // and turn rate from before the re-aim into the new path and lets them die
    // out over reaim_span seconds, so the foot does not stop dead in one tick
    // (docs/gait.md, gait12 and gait14). Zero (reaim_span 0) when no re-aim is
    // being carried.
    vec3 reaim_velocity{0.0f};
    vec3 reaim_spin{0.0f};                    // rad/s about the axis it points along, likewise
    float reaim_time = 0.0f;                  // s since the re-aim
    float reaim_span = 0.0f;                  // s over which the carried velocity dies out
    // The swing's progress over which the foot turns from its start rotation to
    // its target's: from where the step fraction reaches kHoldRotationShare to
    // where it reaches 1 - kHoldRotationShare (docs/gait.md, gait16).
    float turn_from = 0.0f;
    float turn_to = 1.0f;
    // The swing path: ankle height at evenly spaced fractions of the step, clear
    // of the ground under the sole (steps up, box edges), and its arc-length
    // table (the foot's progress along it is by length: docs/gait.md).
    std::array<float, kSwingPathKeys> path_height{};
    ArcLengthTable path_length{};
    // Derived from the fields above when the path is built (begin_swing), and
    // fixed for the swing: its Hermite keys (path_height against the step
    // fraction) and the swing's travel (swing_travel), so a tick evaluates the
    // swing without rebuilding them. Not hashed: a function of hashed fields and
    // the skeleton's proportions, which retune cannot change.
    std::array<HermiteKey, kSwingPathKeys> path_keys{};
    float path_travel = 0.0f;
};

struct GaitState {
    std::array<FootState, 2> feet{};          // 0 left, 1 right
    GaitMode mode = GaitMode::idle;
    float cycle_phase = 0.0f;                 // [0, 1): left contact at 0, right at 0.5
    float speed = 0.0f;                       // along the heading, m/s
    float commanded_speed = 0.0f;             // from the stick, after the slope factor
    float run_blend = 0.0f;                   // 0 walk … 1 run prototypes (follows speed)
    float pelvis_base = 0.0f;                 // smoothed mean ground height under the feet
    vec3 pelvis{0.0f};                        // pelvis joint, world
    float lean = 0.0f;                        // spine lean, radians (follows speed)
    float activity = 0.0f;                    // 0 standing … 1 moving: scales bob and arm swing
    std::int32_t turning_in_place = 0;
    std::int32_t first_step = 0;              // the step from standstill is half length
    std::int32_t steps = 0;                   // landings so far
    std::int32_t flight_phases = 0;           // times both feet left the ground
    std::int32_t flight_phases_open = 0;      // both feet are off the ground now
};

// A prototype as the gait evaluates it: Hermite keys at its phases, tangents from
// the neighbouring keys (Catmull–Rom on uneven phases); a looping path wraps them,
// an open one (the swing) starts and ends at rest. Returns the key count. The
// tuning UI's spline editor draws the same curves (app/ui/spline_panel.cpp).
int build_prototype_keys(const SplinePrototype& p, bool loops, std::array<HermiteKey, kMaxPrototypeKeys>& out);

// Everything the gait needs from the configuration and skeleton, prepared once:
// prototype splines as Hermite keys, bone lengths, offsets.
struct GaitRig {
    struct PrototypeSplines {
        std::array<HermiteKey, kMaxPrototypeKeys> swing_foot{};
        std::array<HermiteKey, kMaxPrototypeKeys> pelvis{};
        std::array<HermiteKey, kMaxPrototypeKeys> hand{};
        int swing_count = 0, pelvis_count = 0, hand_count = 0;
    };
    PrototypeSplines walk;
    PrototypeSplines run;
    float thigh = 0.0f, shin = 0.0f, ankle_height = 0.0f, foot_length = 0.0f, toe_length = 0.0f;
    float hip_half_width = 0.0f, upper_arm = 0.0f, forearm = 0.0f;
    float leg_reach = 0.0f;                   // hip–ankle distance the pelvis keeps within (exact IK zone)
};

GaitRig make_gait_rig(const GaitConfig& config);

// The standing start: feet planted side by side under the hips at `root`.
GaitState initial_gait_state(const GaitConfig& config, const GaitRig& rig, const Terrain& terrain, vec3 root, float heading);

// Stick deflection (0..1) → speed fraction: radial deadzone, then response curve.
float stick_speed_fraction(float deflection, const GaitConfig& config);

// The ground's grade (rise over run) along `heading` at (x, z), over a window
// from 0.4 m behind to 0.8 m ahead: stairs read as their pitch (docs/gait.md).
float ground_grade_along(const Terrain& terrain, float x, float z, float heading);

// The slope factor 1 − slope_speed_factor · degrees of that grade (at least 0.2).
float slope_speed_multiplier(const Terrain& terrain, const GaitConfig& config, float x, float z, float heading);

// The speed the stick commands at (x, z): max_speed × stick fraction × slope
// factor, capped so that the puppet climbs or descends at most 0.6 m/s. The
// gait and gait-eval's speed expectation both use it.
float ground_speed(const Terrain& terrain, const GaitConfig& config, float stick_fraction, float x, float z, float heading);

struct GaitTickInput {
    float stick_x = 0.0f;   // [-1, 1], right
    float stick_y = 0.0f;   // [-1, 1], up (moves toward −Z)
    float dt = 0.0f;
    float breath_time = 0.0f;  // seconds, drives the idle breathing
};

// Advances the gait one tick. root_position and heading are the puppet's (the
// ground point under the pelvis, and the facing angle) and are updated too.
void update_gait(GaitState& gait, vec3& root_position, float& heading, vec2& velocity, const GaitTickInput& input,
                 const GaitConfig& config, const GaitRig& rig, const Terrain& terrain);

// The path a swinging foot's ankle takes from lift-off (its start) to its aimed
// landing (its target): out.size() points at evenly spaced swing progress 0 … 1,
// each where the tick's own swing evaluation would put the ankle then, with the
// rig's prototypes, this run blend and the gait root's heading (the sideways
// swing is along its left). `side`: 0 left foot, 1 right. Returns the points
// written: 0 when the foot stands or out holds fewer than 2. The gait overlay
// draws it (render_es/view.cpp); pure, no allocation.
int sample_swing_path(const FootState& foot, int side, const GaitRig& rig, float run_blend, float heading,
                      std::span<vec3> out);

// The seam: the pose for a gait state. Writes local transforms for the 22-joint
// puppet and runs forward kinematics into the model spans (sizes = joint count).
// A job (runtime/anim/pose_spans.hpp): run() returns false, touching nothing,
// when validate() does.
struct GaitPoseJob {
    const GaitState* gait = nullptr;
    const GaitRig* rig = nullptr;
    const GaitConfig* config = nullptr;
    float heading = 0.0f;
    float breath_time = 0.0f;              // seconds, drives idle breathing
    std::span<const int> parents;
    std::span<const vec3> rest_offsets;
    PoseSpans pose;                        // out: locals and their forward kinematics
    // Optional, built from `parents` (runtime/anim/fk_schedule.hpp): the forward
    // kinematics solves two joints per vector where the CPU has AVX2.
    const FkSchedule* fk_schedule = nullptr;

    // False without a state, rig or config, with spans not of the puppet's joint
    // count, parents out of order (or not the fk_schedule's), a bone length that
    // is not positive, or a state the IK cannot solve (not finite). run() checks this once and then
    // runs the four IK solves and forward kinematics without their own checks
    // (it covers theirs); the rest offsets are the caller's skeleton, not checked.
    bool validate() const;
    [[nodiscard]] bool run() const;
};

}  // namespace marionette
