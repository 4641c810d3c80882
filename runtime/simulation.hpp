#pragma once
// The fixed-timestep simulation: state(k+1) = step(state(k), tick_input(k), config).
// The state is plain, fixed-size data (no pointers, no heap), so it can be copied
// between threads, hashed field by field and compared bit for bit.
#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "runtime/clip.hpp"
#include "runtime/gait.hpp"
#include "runtime/graph_controller.hpp"
#include "runtime/sim_config.hpp"
#include "runtime/terrain.hpp"
#include "runtime/tick_input.hpp"

namespace marionette {

inline constexpr int kMaxJoints = 64;

struct PuppetState {
    std::uint64_t tick = 0;            // ticks completed
    std::int32_t joint_count = 0;
    TickInput input{};                 // the input of the last tick
    vec3 root_position{0.0f};          // ground point under the pelvis, world metres
    vec2 velocity{0.0f};               // world XZ, m/s
    float heading = 0.0f;              // radians; facing (sin h, 0, cos h)
    float walk_phase = 0.0f;           // [0, 1) through the walk cycle
    float idle_time = 0.0f;            // seconds into the idle clip
    float locomotion_blend = 0.0f;     // 0 idle … 1 walking
    GaitState gait{};                  // the spline-IK gait's plan (runtime/gait.hpp)
    std::int32_t motion_source = 0;    // 0: the gait; 1: a motion graph (Simulation::use_motion_graph)
    GraphControllerState graph{};      // the graph controller's state (hashed only when motion_source is 1)
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
    // call then changes nothing and returns the name of the first such key.
    std::string retune(const SimConfig& config);

    const PuppetState& state() const { return state_; }
    const SimConfig& config() const { return config_; }
    const Terrain& terrain() const { return terrain_; }
    const Skeleton& skeleton() const { return graph_ ? graph_->skeleton : idle_clip_.skeleton; }

    // Drives the puppet from a motion graph instead of the gait, from tick 0 (the
    // graph's own skeleton is then the puppet's; its translations are scaled by
    // metres_per_unit). The graph's content hash enters clip_data_hash(), so a log
    // recorded with one graph refuses to replay with another. Throws
    // std::invalid_argument after the first tick (a live switch needs the
    // cross-fade, not implemented) or for a graph the controller refuses.
    void use_motion_graph(std::shared_ptr<const MotionGraph> graph, const GraphControllerConfig& config,
                          double metres_per_unit);
    double tick_seconds() const { return 1.0 / config_.tick_rate_hz; }
    // Hash of the clip data the puppet animates, recorded in input logs.
    std::uint64_t clip_data_hash() const { return clip_data_hash_; }

private:
    void pose_from_gait();
    void step_graph(const TickInput& input, float dt);

    SimConfig config_;
    Terrain terrain_;
    Clip idle_clip_;
    Clip walk_clip_;
    std::uint64_t clip_data_hash_ = 0;
    GaitRig rig_;
    std::shared_ptr<const MotionGraph> graph_;
    std::unique_ptr<GraphController> graph_controller_;
    float metres_per_unit_ = 1.0f;
    PuppetState state_;
};

// The first structural setting (one that cannot change while running: tick rate,
// puppet proportions) that differs between two configurations, or "" when none.
std::string structural_change(const SimConfig& running, const SimConfig& next);

// Sets flush-to-zero / denormals-are-zero on the calling thread, the same way on
// every thread that simulates (run and replay alike): denormals are slow and a
// flag set on one path only would break replay.
void set_simulation_float_mode();

}  // namespace marionette
