#pragma once
// The fixed-timestep simulation: state(k+1) = step(state(k), tick_input(k), config).
// The state is plain, fixed-size data (no pointers, no heap), so it can be copied
// between threads, hashed field by field and compared bit for bit.
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "runtime/anim/clip.hpp"
#include "runtime/errors/outcome.hpp"
#include "runtime/anim/foot_placement.hpp"
#include "runtime/gait/gait.hpp"
#include "runtime/graph/graph_controller.hpp"
#include "runtime/matching/matching_controller.hpp"
#include "runtime/sim/sim_config.hpp"
#include "runtime/ground/terrain.hpp"
#include "runtime/sim/tick_input.hpp"

namespace marionette {

inline constexpr int kMaxJoints = 64;

// What poses the puppet (PuppetState::motion_source); SimConfig's [motion] source
// resolves to one of these (resolve_motion_source).
enum MotionSource : std::int32_t { kSourceGait = 0, kSourceGraph = 1, kSourceGraphFeet = 2, kSourceMatching = 3 };

// A change of motion source in progress: the old source keeps running and its
// pose is blended out over `duration` seconds.
struct MotionFade {
    std::int32_t from = kSourceGait;
    float elapsed = 0.0f;
    float duration = 0.0f;           // 0: no fade running
};

// The gait's own root. Without a graph it is the puppet's root; with one, the
// gait keeps planning from it while the graph (or a fade) places the puppet.
struct GaitRoot {
    vec3 position{0.0f};
    vec2 velocity{0.0f};
    float heading = 0.0f;
};

struct PuppetState {
    std::uint64_t tick = 0;            // ticks completed
    std::int32_t joint_count = 0;
    TickInput input{};                 // the input of the last tick
    vec3 root_position{0.0f};          // ground point under the pelvis, world metres
    vec2 velocity{0.0f};               // world XZ, m/s
    float heading = 0.0f;              // radians; facing (sin h, 0, cos h)
    // walk_phase and locomotion_blend: only hashed (no pose reads them); removing either changes every state
    // hash and golden, so they stay until the next hash-format bump.
    float walk_phase = 0.0f;           // [0, 1): gait.cycle_phase after the last gait tick (hashed only, see above)
    float breath_time = 0.0f;          // s into the breath period: drives the gait's idle breathing
    float locomotion_blend = 0.0f;     // 0 standing … 1 at walk_cycle_speed or faster (hashed only, see above)
    GaitState gait{};                  // the spline-IK gait's plan (runtime/gait/gait.hpp)
    std::int32_t motion_source = kSourceGait;  // MotionSource now posing the puppet (the target of a fade)
    std::int32_t graph_attached = 0;   // 1: a motion graph is attached (the fields below are then hashed)
    MotionFade fade{};
    GaitRoot gait_root{};
    GraphControllerState graph{};      // the graph controller's state
    FootPlacementState feet{};         // graph_feet: pins and body height
    std::int32_t matching_active = 0;  // 1 once motion matching has posed the puppet (the two below are then hashed)
    MatchingState matching{};          // the motion-matching controller's state
    FootPlacementState matching_feet{};  // matching: pins and body height
    std::array<quat, kMaxJoints> local_rotations{};
    std::array<vec3, kMaxJoints> local_translations{};
    std::array<quat, kMaxJoints> model_rotations{};   // world space
    std::array<vec3, kMaxJoints> model_positions{};   // world space
};

// 64-bit xxHash over every field of the state (joints past joint_count excluded),
// fed field by field so padding never enters it.
std::uint64_t hash_state(const PuppetState& state);

class Simulation {
public:
    // Builds the puppet and its clips and keeps a copy of the terrain it walks
    // on (allocates); step() never does. Without a terrain argument the
    // configuration's own terrain (config.terrain) is used.
    explicit Simulation(const SimConfig& config) : Simulation(config, config.terrain) {}
    Simulation(const SimConfig& config, const Terrain& terrain);

    // Advances exactly one tick of 1/tick_rate_hz seconds.
    void step(const TickInput& input);

    // Applies a new configuration at the tick boundary (live tuning). Structural
    // settings (tick rate, puppet proportions) cannot change while running: the
    // call then changes nothing and fails naming the first such key. A new terrain
    // replaces the ground from the next tick on (a copy). A new [motion] source starts a
    // cross-fade; it is refused ("motion.source …") when it needs a graph and none is
    // attached, or crossing between gait and graph when the graph's skeleton is not the puppet's.
    Outcome retune(const SimConfig& config);

    const PuppetState& state() const { return state_; }
    const SimConfig& config() const { return config_; }
    const Terrain& terrain() const { return terrain_; }
    const Skeleton& skeleton() const { return skeleton_from_graph_ ? graph_->skeleton : idle_clip_.skeleton; }

    // Attaches a motion graph before the first tick; the configuration's [motion]
    // source then says whether the graph or the gait poses the puppet, and a later
    // retune may cross-fade between them. When the graph poses the puppet from
    // tick 0, its skeleton is the puppet's (translations scaled by
    // metres_per_unit). The graph's content hash enters clip_data_hash(), so a log
    // recorded with one graph refuses to replay with another. Throws
    // std::invalid_argument after the first tick or for a graph the controller refuses.
    void use_motion_graph(std::shared_ptr<const MotionGraph> graph, const GraphControllerConfig& config,
                          double metres_per_unit);
    // True when the attached graph has the puppet's joints (names and parents), so
    // the gait and the graph can blend into each other.
    bool graph_matches_puppet() const { return graph_matches_puppet_; }
    // The motion-matching database built from the attached graph's locomotion
    // clips (null without a graph, or when its skeleton is not the puppet's).
    const MatchingDatabase* matching_database() const { return matching_db_.get(); }
    // Metres per graph unit of the attached graph's translations (1 without one).
    double metres_per_unit() const { return metres_per_unit_; }
    // Ok when retune would take the [motion] source of `next`, otherwise why not
    // ("motion.source (…)"). Reads only what is fixed once the graph is
    // attached, so another thread may call it while step() runs.
    Outcome motion_source_allowed(const SimConfig& next) const;
    double tick_seconds() const { return 1.0 / config_.tick_rate_hz; }
    // Hash of the clip data the puppet animates, recorded in input logs.
    std::uint64_t clip_data_hash() const { return clip_data_hash_; }

private:
    struct Pose {
        std::array<quat, kMaxJoints> local_rotations{};
        std::array<vec3, kMaxJoints> local_translations{};
        std::array<quat, kMaxJoints> model_rotations{};
        std::array<vec3, kMaxJoints> model_positions{};
        // The first `joints` entries of each array, as the jobs take them.
        PoseSpans spans(size_t joints) {
            return {{local_rotations.data(), joints}, {local_translations.data(), joints},
                    {model_rotations.data(), joints}, {model_positions.data(), joints}};
        }
    };
    // The forward-kinematics schedule of skeleton(): the graph's or the puppet's.
    const FkSchedule& fk_schedule() const { return skeleton_from_graph_ ? graph_fk_schedule_ : puppet_fk_schedule_; }
    void step_gait(const TickInput& input, float dt, const PoseSpans& out);
    void pose_gait(const PoseSpans& out) const;
    size_t gait_joint_count() const { return static_cast<size_t>(idle_clip_.skeleton.joint_count()); }
    void step_graph(const TickInput& input, float dt, Pose& out);
    // keep_above_ground: matching's feet (FootPlacementJob::keep_above_ground); graph_feet's are placed as before.
    void place_feet(const Pose& clip, float dt, Pose& out, FootPlacementState& feet, std::uint8_t contacts,
                    bool keep_above_ground = false);
    void step_matching(const TickInput& input, float dt, Pose& out);
    void attach_matching();
    void begin_source_change(std::int32_t source);
    float graph_heading(quat root_rotation) const;
    void output(const Pose& pose, std::int32_t source, float dt);
    void place_root(const Pose& pose, std::int32_t source, float dt);
    void output_blend(const Pose& from, const Pose& to, float weight, float dt);

    SimConfig config_;
    Terrain terrain_;
    Clip idle_clip_;                   // its skeleton is the puppet's
    FkSchedule puppet_fk_schedule_;    // forward kinematics' order for the puppet's skeleton
    FkSchedule graph_fk_schedule_;     // and for the graph's (empty until a graph is attached)
    std::uint64_t clip_data_hash_ = 0;
    GaitRig rig_;
    std::shared_ptr<const MotionGraph> graph_;
    std::unique_ptr<GraphController> graph_controller_;
    float metres_per_unit_ = 1.0f;
    FootPlacementRig foot_rig_;
    bool graph_matches_puppet_ = false;
    bool skeleton_from_graph_ = false;
    std::vector<MatchingClipRange> matching_clips_;
    // Matching's actions: the graph's clips with no locomotion label, and per
    // graph label the first such clip carrying it (−1: none), for the buttons.
    std::vector<MatchingClipRange> matching_actions_;
    std::vector<std::int32_t> matching_action_of_label_;
    std::unique_ptr<MatchingDatabase> matching_db_;
    std::unique_ptr<MatchingController> matching_;
    Pose gait_pose_, graph_pose_, feet_pose_, blend_pose_, matching_pose_, matching_feet_pose_;  // scratch, rebuilt from the state every tick
    PuppetState state_;
};

// The motion-matching parts of a configuration.
MatchingWeights matching_weights(const SimConfig& config);
MatchingControllerConfig matching_controller_config(const SimConfig& config);

// The MotionSource a configuration asks for, given whether a graph is attached
// (`auto` and the graph sources fall back to the gait without one).
std::int32_t resolve_motion_source(const SimConfig& config, bool graph_attached);

// Ok when no structural setting (one that cannot change while running: tick
// rate, puppet proportions; the terrain can) differs between two configurations,
// otherwise a failure naming the first that does.
Outcome structure_unchanged(const SimConfig& running, const SimConfig& next);

// Sets flush-to-zero / denormals-are-zero on the calling thread, the same way on
// every thread that simulates (run and replay alike): denormals are slow and a
// flag set on one path only would break replay.
void set_simulation_float_mode();

}  // namespace marionette
