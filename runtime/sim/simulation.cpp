#include "runtime/sim/simulation.hpp"

// Static-linking API: lets the hash state live on the stack (no allocation per tick).
#define XXH_STATIC_LINKING_ONLY
#include <xxhash.h>

#include <cmath>
#include <cstring>
#include <initializer_list>
#include <stdexcept>

#include "runtime/math/det_math.hpp"
#include "runtime/gait/puppet.hpp"

#if defined(__x86_64__) || defined(__i386__)
#include <xmmintrin.h>
#endif

namespace marionette {

namespace {
// The bytes hash_state feeds XXH64, gathered into one buffer first: XXH64 of a
// byte string does not depend on how the string was split into updates, so the
// values are those of the field-by-field updates this replaced (each update had
// a fixed cost of its own; ~90 of them made the hash ~40 % of an idle tick). Past
// the buffer's size the bytes stream through XXH64's state.
class HashBytes {
public:
    void add(const void* bytes, size_t n) {
        if (used_ + n > sizeof buffer_) flush();
        if (n > sizeof buffer_) {
            XXH64_update(&stream_, bytes, n);
            return;
        }
        std::memcpy(buffer_ + used_, bytes, n);
        used_ += n;
    }
    std::uint64_t digest() {
        if (!streaming_) return XXH64(buffer_, used_, 0);
        flush();
        return XXH64_digest(&stream_);
    }

private:
    void flush() {
        if (!streaming_) XXH64_reset(&stream_, 0);
        streaming_ = true;
        XXH64_update(&stream_, buffer_, used_);
        used_ = 0;
    }
    unsigned char buffer_[8192];
    size_t used_ = 0;
    bool streaming_ = false;
    XXH64_state_t stream_;
};

float clampf(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }

void hash_floats(HashBytes& h, const float* v, size_t n) { h.add(v, n * sizeof(float)); }
void hash_ints(HashBytes& h, std::initializer_list<std::int32_t> v) { h.add(v.begin(), v.size() * sizeof(std::int32_t)); }
void hash_vec(HashBytes& h, vec3 v) {
    const float f[3] = {v.x, v.y, v.z};
    hash_floats(h, f, 3);
}
void hash_quat(HashBytes& h, quat q) {
    const float f[4] = {q.w, q.x, q.y, q.z};
    hash_floats(h, f, 4);
}

// Every field of the gait state, one by one (no padding enters the hash).
void hash_gait(HashBytes& h, const GaitState& g) {
    for (const FootState& f : g.feet) {
        hash_vec(h, f.ankle);
        hash_quat(h, f.rotation);
        hash_vec(h, f.start);
        hash_quat(h, f.start_rotation);
        hash_vec(h, f.target);
        hash_quat(h, f.target_rotation);
        const float scalars[9] = {f.ground, f.start_ground, f.target_ground, f.progress, f.fraction, f.lift_phase, f.timed_rate, f.lift_scale,
                                  f.reach_carry};
        hash_floats(h, scalars, 9);
        hash_floats(h, f.path_height.data(), f.path_height.size());
        hash_floats(h, f.path_length.length.data(), f.path_length.length.size());
        hash_ints(h, {f.swinging, f.replanned});
        // Only while a re-aim's velocity is carried: the states without one hash
        // as they did before the fields existed.
        if (f.reaim_span > 0.0f) {
            hash_vec(h, f.reaim_velocity);
            hash_vec(h, f.reaim_spin);
            const float carry[2] = {f.reaim_time, f.reaim_span};
            hash_floats(h, carry, 2);
        }
        const float plan[2] = {f.planned_speed, f.planned_heading};
        hash_floats(h, plan, 2);
        if (f.swinging) {
            const float turn[2] = {f.turn_from, f.turn_to};
            hash_floats(h, turn, 2);
        }
        // Only for a swing turning over half its step (beside a wall): the
        // others hash as they did before the field existed.
        if (f.turn_order != 0) hash_ints(h, {f.turn_order});
    }
    hash_vec(h, g.pelvis);
    const float scalars[7] = {g.cycle_phase, g.speed, g.commanded_speed, g.run_blend, g.pelvis_base, g.lean, g.activity};
    hash_floats(h, scalars, 7);
    hash_ints(h, {static_cast<std::int32_t>(g.mode), g.turning_in_place, g.first_step, g.steps, g.flight_phases, g.flight_phases_open});
}
// The graph controller's state, field by field (gait-driven states skip it, so
// their hashes are what they were before the graph existed).
void hash_graph(HashBytes& h, std::int32_t source, const GraphControllerState& g) {
    hash_ints(h, {source, g.edge, static_cast<std::int32_t>(g.mode), g.last_buttons, g.action_label,
                  g.action_path_length, g.action_path_next, g.search_depth, g.best_edge, g.contacts});
    const double world[3] = {g.world_angle, g.world_dx, g.world_dz};
    h.add(world, sizeof world);
    const float scalars[5] = {g.edge_position, g.idle_seconds, g.best_score, g.desired_vx, g.desired_vz};
    hash_floats(h, scalars, 5);
    const std::int64_t counters[6] = {g.decisions, g.transitions_taken, g.actions_played, g.nodes_expanded,
                                      static_cast<std::int64_t>(g.rng), g.action_search_pops};
    h.add(counters, sizeof counters);
    h.add(g.action_path.data(), g.action_path.size() * sizeof(std::int32_t));
    for (const GraphSearchLevel& l : g.search) {
        hash_ints(h, {l.node, l.next_edge, l.first_edge});
        const float f[2] = {l.seconds, l.cost};
        hash_floats(h, f, 2);
        const double w[3] = {l.angle, l.dx, l.dz};
        h.add(w, sizeof w);
    }
}
// The matching controller's state and its feet, field by field.
void hash_matching(HashBytes& h, const MatchingState& m, const FootPlacementState& feet, size_t joints) {
    hash_ints(h, {m.frame, m.contacts, feet.started, feet.feet[0].contact, feet.feet[1].contact, m.action, m.held_buttons});
    const double world[3] = {m.world_angle, m.world_dx, m.world_dz};
    h.add(world, sizeof world);
    const TrajectorySpring& sp = m.spring;
    const float f[15] = {m.frame_time, sp.px,          sp.pz,          sp.vx,          sp.vz,
                         sp.ax,        sp.az,          sp.heading,     sp.heading_rate, m.since_search,
                         m.since_jump, m.last_cost,    feet.body_offset, feet.reach_drop, feet.reach_drop_velocity};
    hash_floats(h, f, 15);
    const std::int64_t counters[2] = {m.searches, m.jumps};
    h.add(counters, sizeof counters);
    for (size_t j = 0; j < joints && j < m.offset_rotation.size(); ++j) {
        hash_vec(h, m.offset_rotation[j]);
        hash_vec(h, m.offset_angular_velocity[j]);
        hash_vec(h, m.offset_translation[j]);
        hash_vec(h, m.offset_velocity[j]);
    }
    for (const FootPin& p : feet.feet) {
        hash_vec(h, p.pin);
        hash_vec(h, p.placed);
        hash_vec(h, p.clip_previous);
        const float w[3] = {p.ground, p.release, p.plant};
        hash_floats(h, w, 3);
    }
}
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
    puppet_fk_schedule_ = FkSchedule(idle_clip_.skeleton.parents);
    // The walk clip is built only for this hash, which every input log records:
    // dropping it refuses every existing log; it goes with the next log-format bump.
    const Clip walk_clip = make_walk_clip(skeleton, config_);
    clip_data_hash_ = hash_clip(idle_clip_) ^ (hash_clip(walk_clip) * 0x9E3779B97F4A7C15ull);
    // Tick 0: standing on the terrain at the origin, so even a run of no ticks has a full pose.
    state_.joint_count = skeleton.joint_count();
    rig_ = make_gait_rig(config_);
    state_.gait = initial_gait_state(config_, rig_, terrain_, vec3(0.0f), 0.0f);
    state_.gait_root.position = vec3(0.0f, state_.gait.pelvis_base, 0.0f);
    pose_gait(gait_pose_.spans(gait_joint_count()));
    output(gait_pose_, kSourceGait, 0.0f);
}

std::int32_t resolve_motion_source(const SimConfig& config, bool graph_attached) {
    if (!graph_attached) return kSourceGait;
    switch (config.motion_source) {
        case MotionSourceSetting::gait: return kSourceGait;
        case MotionSourceSetting::graph_feet: return kSourceGraphFeet;
        case MotionSourceSetting::matching: return kSourceMatching;
        case MotionSourceSetting::automatic:
        case MotionSourceSetting::graph: break;
    }
    return kSourceGraph;
}

Outcome structure_unchanged(const SimConfig& c, const SimConfig& next) {
    if (next.tick_rate_hz != c.tick_rate_hz) return Outcome::failure("simulation.tick_rate_hz");
    const float SimConfig::*const structural[] = {
        &SimConfig::pelvis_height, &SimConfig::hip_width, &SimConfig::thigh_length, &SimConfig::shin_length,
        &SimConfig::ankle_height, &SimConfig::foot_length, &SimConfig::toe_length, &SimConfig::spine_length,
        &SimConfig::neck_length, &SimConfig::head_length, &SimConfig::shoulder_width,
        &SimConfig::upper_arm_length, &SimConfig::forearm_length, &SimConfig::hand_length};
    for (auto field : structural)
        if (next.*field != c.*field) return Outcome::failure("puppet (skeleton proportions)");
    return Outcome::success();  // the terrain may change: retune swaps the ground at the tick boundary
}

Outcome Simulation::retune(const SimConfig& next) {
    if (Outcome kept = structure_unchanged(config_, next); !kept.ok()) return kept;
    if (Outcome allowed = motion_source_allowed(next); !allowed.ok()) return allowed;
    const std::int32_t source = resolve_motion_source(next, graph_ != nullptr);
    const std::int32_t current = state_.motion_source;
    const bool reweigh = matching_db_ && !(matching_weights(next) == matching_weights(config_));
    // A terrain edit (the tuning UI's terrain editor, a file edit): every ground
    // query from the next tick on sees the new surface. A simulation built on a
    // terrain of its own keeps it while the configuration's terrain stays put.
    if (!(next.terrain == config_.terrain)) terrain_ = next.terrain;
    config_ = next;
    rig_ = make_gait_rig(config_);
    if (matching_) matching_->set_config(matching_controller_config(config_));
    if (reweigh) normalise_matching_database(*matching_db_, matching_weights(config_));
    if (source != current) begin_source_change(source);
    return Outcome::success();
}

Outcome Simulation::motion_source_allowed(const SimConfig& next) const {
    const bool wants_graph = next.motion_source == MotionSourceSetting::graph ||
                             next.motion_source == MotionSourceSetting::graph_feet ||
                             next.motion_source == MotionSourceSetting::matching;
    if (!graph_ && wants_graph)
        return Outcome::failure("motion.source (no motion graph is attached: start with --graph, or with this source in the configuration)");
    const std::int32_t source = resolve_motion_source(next, graph_ != nullptr);
    // Without a shared skeleton the puppet never leaves the family (gait or
    // graph) it started in, so comparing with the start is the same as with now.
    if ((source == kSourceGait) == skeleton_from_graph_ && !graph_matches_puppet_ && graph_)
        return Outcome::failure("motion.source (the motion graph's skeleton is not the puppet's, so gait and graph cannot blend)");
    if (source == kSourceGraphFeet && !foot_rig_.valid)
        return Outcome::failure("motion.source (graph_feet: the motion graph names no foot joints with a knee and a hip)");
    if (source == kSourceMatching && !matching_)
        return Outcome::failure("motion.source (matching: the motion graph's skeleton is not the puppet's, or it has no walking clips with feet)");
    return Outcome::success();
}

void Simulation::use_motion_graph(std::shared_ptr<const MotionGraph> graph, const GraphControllerConfig& config,
                                  double metres_per_unit) {
    if (state_.tick != 0) throw std::invalid_argument("a motion graph can only be attached before the first tick");
    if (!graph) throw std::invalid_argument("no motion graph given");
    if (graph_) throw std::invalid_argument("a motion graph is already attached");
    if (graph->joint_count() > kMaxJoints) throw std::invalid_argument("motion graph skeleton has too many joints");
    if (!(metres_per_unit > 0.0)) throw std::invalid_argument("metres_per_unit must be positive");
    auto controller = std::make_unique<GraphController>(*graph, config);  // validates the graph
    FootPlacementRig foot_rig =
        make_foot_placement_rig(std::span<const int>(graph->skeleton.parents), graph->left_foot, graph->right_foot);
    add_foot_tips(foot_rig, graph->skeleton.parents, graph->skeleton.end_site_parents, graph->skeleton.end_site_offsets,
                  static_cast<float>(metres_per_unit));
    const std::int32_t source = resolve_motion_source(config_, true);
    if (source == kSourceGraphFeet && !foot_rig.valid)
        throw std::invalid_argument("motion.source graph_feet: the motion graph names no foot joints with a knee and a hip");
    const Skeleton& puppet = idle_clip_.skeleton;
    graph_matches_puppet_ = graph->skeleton.parents == puppet.parents && graph->skeleton.joint_names == puppet.joint_names;
    const std::vector<std::uint8_t> bytes = serialize_motion_graph(*graph);
    clip_data_hash_ ^= XXH64(bytes.data(), bytes.size(), 0x6D67726170680001ull);
    graph_fk_schedule_ = FkSchedule(graph->skeleton.parents);
    graph_ = std::move(graph);
    graph_controller_ = std::move(controller);
    foot_rig_ = foot_rig;
    metres_per_unit_ = static_cast<float>(metres_per_unit);
    skeleton_from_graph_ = source != kSourceGait;
    state_.graph_attached = 1;
    state_.motion_source = source;
    state_.joint_count = skeleton().joint_count();
    state_.graph = graph_controller_->initial_state();
    attach_matching();
    if (source == kSourceMatching && !matching_)
        throw std::invalid_argument("motion.source matching: the motion graph's skeleton is not the puppet's, or it has no walking clips with feet");
    if (source == kSourceGait) return;
    if (source == kSourceMatching) {
        state_.matching = matching_->initial_state(vec3(0.0f), 0.0f);
        state_.matching_active = 1;
        step_matching(TickInput{}, 0.0f, matching_pose_);
        place_feet(matching_pose_, 0.0f, matching_feet_pose_, state_.matching_feet, state_.matching.contacts, true);
        output(matching_feet_pose_, source, 0.0f);
        return;
    }
    step_graph(TickInput{}, 0.0f, graph_pose_);
    if (source == kSourceGraphFeet) {
        place_feet(graph_pose_, 0.0f, feet_pose_, state_.feet, state_.graph.contacts);
        output(feet_pose_, source, 0.0f);
    } else {
        output(graph_pose_, source, 0.0f);
    }
}

void Simulation::step_graph(const TickInput& input, float dt, Pose& out) {
    PuppetState& s = state_;
    const size_t n = static_cast<size_t>(graph_->joint_count());
    GraphControllerInput in;
    in.stick_x = static_cast<float>(input.left_x) / kStickScale;
    in.stick_y = static_cast<float>(input.left_y) / kStickScale;
    in.buttons = input.buttons;
    in.dt = dt;
    const PoseSpans pose = out.spans(n);
    const LocalPoseOutput local{pose.local_rotations, pose.local_translations};
    expect_job_ran(dt > 0.0f ? graph_controller_->step(s.graph, in, local) : graph_controller_->pose(s.graph, local));
    for (size_t j = 0; j < n; ++j) out.local_translations[j] *= metres_per_unit_;
    expect_job_ran(LocalToModelJob{std::span<const int>(graph_->skeleton.parents), pose.local(), pose.model(), &graph_fk_schedule_}.run());
}

void Simulation::place_feet(const Pose& clip, float dt, Pose& out, FootPlacementState& feet, std::uint8_t contacts,
                            bool keep_above_ground) {
    out = clip;
    const size_t n = static_cast<size_t>(graph_->joint_count());
    const FootPlacementJob job{&feet,
                               &foot_rig_,
                               &terrain_,
                               contacts,
                               dt,
                               config_.feet_release_s,
                               config_.feet_terrain_rate,
                               std::span<const int>(graph_->skeleton.parents),
                               out.spans(n),
                               keep_above_ground,
                               keep_above_ground};
    expect_job_ran(job.run());
}

void Simulation::pose_gait(const PoseSpans& out) const {
    const Skeleton& puppet = idle_clip_.skeleton;
    const GaitPoseJob job{&state_.gait,
                          &rig_,
                          &config_,
                          state_.gait_root.heading,
                          state_.breath_time,
                          std::span<const int>(puppet.parents),
                          std::span<const vec3>(puppet.rest_offsets),
                          out,
                          &puppet_fk_schedule_};
    expect_job_ran(job.run());
}

void Simulation::step_gait(const TickInput& input, float dt, const PoseSpans& out) {
    const SimConfig& c = config_;
    PuppetState& s = state_;
    // The gait plans (stick → velocity, steps, pelvis); the pose comes from its state.
    GaitTickInput gait_input;
    gait_input.stick_x = static_cast<float>(input.left_x) / kStickScale;
    gait_input.stick_y = static_cast<float>(input.left_y) / kStickScale;
    gait_input.dt = dt;
    gait_input.breath_time = s.breath_time;
    update_gait(s.gait, s.gait_root.position, s.gait_root.heading, s.gait_root.velocity, gait_input, c, rig_, terrain_);
    s.locomotion_blend = clampf(s.gait.speed / c.walk_cycle_speed, 0.0f, 1.0f);
    s.walk_phase = s.gait.cycle_phase;
    s.breath_time += dt;
    if (s.breath_time >= c.breath_period_s) s.breath_time -= c.breath_period_s;
    pose_gait(out);
}

namespace {
float heading_of(quat root_rotation) {
    const vec3 forward = quat_rotate(root_rotation, vec3(0.0f, 0.0f, 1.0f));
    return static_cast<float>(det::atan2(forward.x, forward.z));
}
float smoothstep(float u) { return u * u * (3.0f - 2.0f * u); }
}  // namespace

// The facing of a graph pose: the root's +Z turned by the graph's facing offset
// (the clips' forward as the controller measured it from their travel).
float Simulation::graph_heading(quat root_rotation) const {
    return static_cast<float>(det::wrap_angle(heading_of(root_rotation) + graph_controller_->facing_offset()));
}

// Where a source puts the puppet's root (ground point under the pelvis) and which way it faces.
void Simulation::output(const Pose& pose, std::int32_t source, float dt) {
    PuppetState& s = state_;
    const size_t n = static_cast<size_t>(s.joint_count);
    for (size_t j = 0; j < n; ++j) {
        s.local_rotations[j] = pose.local_rotations[j];
        s.local_translations[j] = pose.local_translations[j];
        s.model_rotations[j] = pose.model_rotations[j];
        s.model_positions[j] = pose.model_positions[j];
    }
    place_root(pose, source, dt);
}

// The root and facing of the output (for the gait, its own root: the pose is not read).
void Simulation::place_root(const Pose& pose, std::int32_t source, float dt) {
    PuppetState& s = state_;
    if (source == kSourceGait) {
        s.root_position = s.gait_root.position;
        s.velocity = s.gait_root.velocity;
        s.heading = s.gait_root.heading;
        return;
    }
    const size_t root = static_cast<size_t>(foot_rig_.root);
    const vec3 p = pose.model_positions[root];
    const vec2 before(s.root_position.x, s.root_position.z);
    s.root_position = vec3(p.x, source == kSourceGraphFeet ? s.feet.body_offset : (source == kSourceMatching ? s.matching_feet.body_offset : 0.0f), p.z);
    if (dt > 0.0f) s.velocity = (vec2(p.x, p.z) - before) / dt;
    s.heading = graph_heading(pose.model_rotations[root]);
}

// The cross-fade of a change of source: local rotations slerped, translations
// and roots lerped, headings along the shorter arc (both sources share the
// puppet's skeleton: retune refuses otherwise).
void Simulation::output_blend(const Pose& from, const Pose& to, float weight, float dt) {
    PuppetState& s = state_;
    const size_t n = static_cast<size_t>(s.joint_count);
    auto root_of = [&](std::int32_t source, const Pose& pose, vec3& position, float& heading) {
        if (source == kSourceGait) {
            position = s.gait_root.position;
            heading = s.gait_root.heading;
            return;
        }
        const size_t root = static_cast<size_t>(foot_rig_.root);
        const float body = source == kSourceGraphFeet ? s.feet.body_offset
                                                      : (source == kSourceMatching ? s.matching_feet.body_offset : 0.0f);
        position = vec3(pose.model_positions[root].x, body, pose.model_positions[root].z);
        heading = graph_heading(pose.model_rotations[root]);
    };
    vec3 p_from, p_to;
    float h_from = 0.0f, h_to = 0.0f;
    root_of(s.fade.from, from, p_from, h_from);
    root_of(s.motion_source, to, p_to, h_to);
    for (size_t j = 0; j < n; ++j) {
        s.local_rotations[j] = quat_slerp(from.local_rotations[j], to.local_rotations[j], weight);
        s.local_translations[j] = lerp(from.local_translations[j], to.local_translations[j], weight);
    }
    const LocalToModelJob fk{std::span<const int>(skeleton().parents),
                             {std::span<const quat>(s.local_rotations.data(), n), std::span<const vec3>(s.local_translations.data(), n)},
                             {std::span<quat>(s.model_rotations.data(), n), std::span<vec3>(s.model_positions.data(), n)},
                             &fk_schedule()};
    expect_job_ran(fk.run());
    const vec2 before(s.root_position.x, s.root_position.z);
    s.root_position = lerp(p_from, p_to, weight);
    if (dt > 0.0f) s.velocity = (vec2(s.root_position.x, s.root_position.z) - before) / dt;
    s.heading = static_cast<float>(det::wrap_angle(h_from + det::wrap_angle(static_cast<double>(h_to) - h_from) * weight));
}

void Simulation::begin_source_change(std::int32_t source) {
    PuppetState& s = state_;
    const std::int32_t current = s.motion_source;
    if (s.fade.duration > 0.0f && s.fade.from == source) {
        // Back to where a running fade came from: the same fade, run backwards.
        s.fade.from = current;
        s.fade.elapsed = s.fade.duration - s.fade.elapsed;
        s.motion_source = source;
        return;
    }
    if (source == kSourceGait) {
        // The gait starts standing where the puppet is, facing its way.
        const vec3 p = s.root_position;
        s.gait = initial_gait_state(config_, rig_, terrain_, vec3(p.x, 0.0f, p.z), s.heading);
        s.gait_root.position = vec3(p.x, s.gait.pelvis_base, p.z);
        s.gait_root.velocity = vec2(0.0f);
        s.gait_root.heading = s.heading;
    } else if (source == kSourceMatching) {
        // Matching starts from where the puppet is, facing its way, its springs at rest.
        matching_->place(s.matching, s.root_position, s.heading);
        s.matching_feet = FootPlacementState{};
        s.matching_active = 1;
        // A button held across the switch is not a press: presses count from
        // the buttons held now, not from when matching last ran.
        s.matching.held_buttons = s.input.buttons;
    } else if (current == kSourceGait || current == kSourceMatching) {
        // Re-place the graph's motion so its root is where the puppet is, facing its way.
        const size_t n = static_cast<size_t>(graph_->joint_count());
        const PoseSpans blend = blend_pose_.spans(n);
        expect_job_ran(graph_controller_->pose(s.graph, {blend.local_rotations, blend.local_translations}));
        const size_t root = static_cast<size_t>(foot_rig_.root);
        const vec3 r = blend_pose_.local_translations[root];
        const double turn = det::wrap_angle(static_cast<double>(s.heading) - graph_heading(blend_pose_.local_rotations[root]));
        double sn = 0.0, cs = 0.0;
        det::sin_cos(turn, sn, cs);
        const PlanarTransform anchor{turn, s.root_position.x / metres_per_unit_ - (cs * r.x + sn * r.z),
                                     s.root_position.z / metres_per_unit_ - (-sn * r.x + cs * r.z)};
        const PlanarTransform world = compose_planar(anchor, {s.graph.world_angle, s.graph.world_dx, s.graph.world_dz});
        s.graph.world_angle = world.angle, s.graph.world_dx = world.dx, s.graph.world_dz = world.dz;
        s.graph.search_depth = -1;  // the look-ahead was placed in the old frame: start it again
        s.graph.best_edge = -1;
        s.graph.last_buttons = s.input.buttons;  // held across the switch: not a press
    }
    if (source == kSourceGraphFeet) s.feet = FootPlacementState{};
    s.fade = MotionFade{};
    if (config_.motion_crossfade_s > 0.0f) s.fade = MotionFade{current, 0.0f, config_.motion_crossfade_s};
    s.motion_source = source;
}

void Simulation::step(const TickInput& input) {
    const float dt = 1.0f / static_cast<float>(config_.tick_rate_hz);
    PuppetState& s = state_;
    s.input = input;
    const bool fading = s.fade.duration > 0.0f;
    const std::int32_t to = s.motion_source;
    const std::int32_t from = fading ? s.fade.from : to;
    // Every source in play advances (a fading one too, so its pose keeps moving).
    auto uses = [&](std::int32_t a, std::int32_t b) { return to == a || from == a || to == b || from == b; };
    // The gait alone, not fading: its pose is written straight into the state
    // (the same bits output() would copy there from gait_pose_, which nothing
    // else reads this tick; a copy of four joint arrays saved per tick).
    const size_t gait_joints = gait_joint_count();
    const bool gait_only = !fading && to == kSourceGait && static_cast<size_t>(s.joint_count) == gait_joints;
    if (gait_only) {
        const PoseSpans direct{{s.local_rotations.data(), gait_joints}, {s.local_translations.data(), gait_joints},
                               {s.model_rotations.data(), gait_joints}, {s.model_positions.data(), gait_joints}};
        step_gait(input, dt, direct);
        place_root(gait_pose_, kSourceGait, dt);
        ++s.tick;
        return;
    }
    if (uses(kSourceGait, kSourceGait)) step_gait(input, dt, gait_pose_.spans(gait_joints));
    if (uses(kSourceGraph, kSourceGraphFeet)) step_graph(input, dt, graph_pose_);
    if (uses(kSourceGraphFeet, kSourceGraphFeet)) place_feet(graph_pose_, dt, feet_pose_, s.feet, s.graph.contacts);
    if (uses(kSourceMatching, kSourceMatching)) {
        step_matching(input, dt, matching_pose_);
        place_feet(matching_pose_, dt, matching_feet_pose_, s.matching_feet, s.matching.contacts, true);
    }
    auto pose_of = [&](std::int32_t source) -> const Pose& {
        switch (source) {
            case kSourceGait: return gait_pose_;
            case kSourceGraph: return graph_pose_;
            case kSourceGraphFeet: return feet_pose_;
            default: return matching_feet_pose_;
        }
    };
    if (!fading) {
        output(pose_of(to), to, dt);
    } else {
        s.fade.elapsed += dt;
        const float u = s.fade.elapsed >= s.fade.duration ? 1.0f : s.fade.elapsed / s.fade.duration;
        output_blend(pose_of(from), pose_of(to), smoothstep(u), dt);
        if (u >= 1.0f) s.fade = MotionFade{};
    }
    ++s.tick;
}

std::uint64_t hash_state(const PuppetState& s) {
    HashBytes h;
    h.add(&s.tick, sizeof s.tick);
    h.add(&s.joint_count, sizeof s.joint_count);
    const std::int16_t axes[4] = {s.input.left_x, s.input.left_y, s.input.right_x, s.input.right_y};
    const std::uint16_t triggers[2] = {s.input.left_trigger, s.input.right_trigger};
    h.add(axes, sizeof axes);
    h.add(triggers, sizeof triggers);
    h.add(&s.input.buttons, sizeof s.input.buttons);
    const float scalars[8] = {s.root_position.x, s.root_position.y, s.root_position.z, s.velocity.x,
                              s.velocity.y, s.heading, s.walk_phase, s.breath_time};
    hash_floats(h, scalars, 8);
    hash_floats(h, &s.locomotion_blend, 1);
    hash_gait(h, s.gait);
    if (s.graph_attached) {
        hash_graph(h, s.motion_source, s.graph);
        hash_ints(h, {s.fade.from, s.feet.started, s.feet.feet[0].contact, s.feet.feet[1].contact});
        const float blend[6] = {s.fade.elapsed, s.fade.duration, s.gait_root.velocity.x, s.gait_root.velocity.y,
                                s.gait_root.heading, s.feet.body_offset};
        hash_floats(h, blend, 6);
        hash_vec(h, s.gait_root.position);
        for (const FootPin& f : s.feet.feet) {
            hash_vec(h, f.pin);
            hash_vec(h, f.placed);
            hash_vec(h, f.clip_previous);
            const float weights[3] = {f.ground, f.release, f.plant};
            hash_floats(h, weights, 3);
        }
    }
    if (s.matching_active) hash_matching(h, s.matching, s.matching_feet, static_cast<size_t>(s.joint_count));
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
    return h.digest();
}

}  // namespace marionette

namespace marionette {

MatchingWeights matching_weights(const SimConfig& c) {
    MatchingWeights w;
    w.foot_position = c.matching_foot_position_weight;
    w.foot_velocity = c.matching_foot_velocity_weight;
    w.hips_velocity = c.matching_hips_velocity_weight;
    w.trajectory_position = c.matching_trajectory_position_weight;
    w.trajectory_facing = c.matching_trajectory_facing_weight;
    return w;
}

MatchingControllerConfig matching_controller_config(const SimConfig& c) {
    MatchingControllerConfig m;
    m.search_interval_s = c.matching_search_interval_s;
    m.search_threshold_m = c.matching_search_threshold_m;
    m.inertialization_s = c.matching_inertialization_s;
    m.velocity_halflife_s = c.matching_velocity_halflife_s;
    m.facing_halflife_s = c.matching_facing_halflife_s;
    m.correction_halflife_s = c.matching_correction_halflife_s;
    return m;
}

// The database from the attached graph's locomotion clips (labels walk, run,
// idle, turn, stop; every clip when none has them), when the graph has the
// puppet's skeleton and feet. Allocates: only when a graph is attached.
void Simulation::attach_matching() {
    if (!graph_matches_puppet_ || !foot_rig_.valid) return;
    const MotionGraph& g = *graph_;
    std::uint32_t locomotion = 0;
    for (const char* label : {"walk", "run", "idle", "turn", "stop"})
        if (const int b = g.label_index(label); b >= 0) locomotion |= 1u << b;
    matching_clips_.clear();
    matching_actions_.clear();
    matching_action_of_label_.assign(g.labels.size(), -1);
    for (const GraphClip& c : g.clips) {
        if (locomotion == 0 || (c.label_mask & locomotion) != 0) {
            matching_clips_.push_back({c.first_frame, c.frame_count});
        } else if (c.label_mask != 0 && c.frame_count >= 2) {
            for (size_t b = 0; b < matching_action_of_label_.size(); ++b)
                if (((c.label_mask >> b) & 1u) && matching_action_of_label_[b] < 0)
                    matching_action_of_label_[b] = static_cast<std::int32_t>(matching_actions_.size());
            matching_actions_.push_back({c.first_frame, c.frame_count});
        }
    }
    MatchingSource source;
    source.parents = std::span<const int>(g.skeleton.parents);
    source.rotations = g.rotations;
    source.translations = g.translations;
    source.contacts = g.contacts;
    source.clips = matching_clips_;
    source.actions = matching_actions_;
    source.frame_rate = g.frame_rate;
    source.metres_per_unit = metres_per_unit_;
    source.facing_offset = graph_controller_->facing_offset();
    source.left_foot = g.left_foot;
    source.right_foot = g.right_foot;
    auto db = std::make_unique<MatchingDatabase>();
    if (!build_matching_database(source, matching_weights(config_), *db).ok()) return;
    matching_db_ = std::move(db);
    matching_ = std::make_unique<MatchingController>(source, *matching_db_, matching_controller_config(config_));
}

// Stick → desired velocity and facing with the gait's own response (dead zone,
// response curve, max_speed, slope slow-down), then the matching controller.
void Simulation::step_matching(const TickInput& input, float dt, Pose& out) {
    PuppetState& s = state_;
    const float sx = static_cast<float>(input.left_x) / kStickScale;
    const float sy = static_cast<float>(input.left_y) / kStickScale;
    const float length = std::sqrt(sx * sx + sy * sy);
    const float fraction = stick_speed_fraction(length < 1.0f ? length : 1.0f, config_);
    MatchingInput in;
    in.dt = dt;
    in.goal.heading = s.matching.spring.heading;
    // A newly pressed button mapped to a label with an action clip plays it
    // (the graph's [motion_graph.buttons] map, as in graph mode).
    const std::uint16_t pressed = static_cast<std::uint16_t>(input.buttons & ~s.matching.held_buttons);
    if (dt > 0.0f) s.matching.held_buttons = static_cast<std::uint16_t>(input.buttons);
    const GraphControllerConfig& graph_config = graph_controller_->config();
    for (int b = 0; b < kGraphActionButtons && pressed != 0 && dt > 0.0f; ++b) {
        const int label = graph_config.button_label[static_cast<size_t>(b)];
        if (!((pressed >> b) & 1u) || label < 0 || static_cast<size_t>(label) >= matching_action_of_label_.size()) continue;
        if (matching_action_of_label_[static_cast<size_t>(label)] < 0) continue;
        in.action = matching_action_of_label_[static_cast<size_t>(label)];
        break;
    }
    if (fraction > 0.0f) {
        const float dx = sx / length, dz = -sy / length;
        in.goal.heading = static_cast<float>(det::atan2(dx, dz));
        const float speed = ground_speed(terrain_, config_, fraction, s.matching.spring.px, s.matching.spring.pz, in.goal.heading);
        in.goal.vx = dx * speed;
        in.goal.vz = dz * speed;
    }
    const size_t n = static_cast<size_t>(graph_->joint_count());
    const PoseSpans pose = out.spans(n);
    const LocalPoseOutput local{pose.local_rotations, pose.local_translations};
    expect_job_ran(dt > 0.0f ? matching_->step(s.matching, in, local) : matching_->pose(s.matching, local));
    expect_job_ran(LocalToModelJob{std::span<const int>(graph_->skeleton.parents), pose.local(), pose.model(), &graph_fk_schedule_}.run());
}

}  // namespace marionette
