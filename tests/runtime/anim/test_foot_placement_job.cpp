// FootPlacementJob (runtime/anim/foot_placement.hpp): feet pinned and stood on
// the terrain over a clip pose, as a job.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <vector>

#include "runtime/anim/foot_placement.hpp"
#include "runtime/anim/skeleton.hpp"
#include "runtime/anim/two_bone_ik.hpp"
#include "tests/alloc_counter.hpp"
#include "tests/job_sentinel.hpp"

using namespace marionette;

namespace {
// The generated cases' fixed-seed generator: uniform floats in [0, 1).
struct Lcg {
    std::uint32_t seed;
    float next() {
        seed = seed * 1664525u + 1013904223u;
        return static_cast<float>(seed >> 8) / 16777216.0f;
    }
};
float norm_of(vec3 v) { return std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z); }
float distance_of(vec3 a, vec3 b) { return norm_of(b - a); }

// Pelvis, then each leg hip → knee → ankle: thigh 0.45 m, shin 0.43 m.
constexpr int kLeftAnkle = 3, kRightAnkle = 6;
constexpr std::uint8_t kBothFeetInContact = 3;  // contact bits: 1 left, 2 right
const std::vector<int> kLegParents = {kNoParent, 0, 1, 2, 0, 4, 5};

// The clip pose: knees bent (so the IK can reach a target straight below the
// clip's ankle exactly), with its forward kinematics.
struct ClipPose {
    std::vector<quat> local_rotations = std::vector<quat>(7, quat_identity());
    std::vector<vec3> local_translations = {vec3(0.0f, 0.9f, 0.0f),   vec3(0.1f, 0.0f, 0.0f),  vec3(0.0f, -0.45f, 0.0f),
                                            vec3(0.0f, -0.43f, 0.0f), vec3(-0.1f, 0.0f, 0.0f), vec3(0.0f, -0.45f, 0.0f),
                                            vec3(0.0f, -0.43f, 0.0f)};
    std::vector<quat> model_rotations = std::vector<quat>(7);
    std::vector<vec3> model_positions = std::vector<vec3>(7);
    ClipPose() {
        for (const int hip : {1, 4}) {
            local_rotations[static_cast<size_t>(hip)] = quat_axis_angle(vec3(1.0f, 0.0f, 0.0f), -0.3);
            local_rotations[static_cast<size_t>(hip) + 1] = quat_axis_angle(vec3(1.0f, 0.0f, 0.0f), 0.6);
        }
        REQUIRE(LocalToModelJob{kLegParents, {local_rotations, local_translations}, {model_rotations, model_positions}}.run());
    }
    PoseSpans spans() { return {local_rotations, local_translations, model_rotations, model_positions}; }
};

Terrain raised_ground(float top) {
    Terrain t;
    t.boxes.push_back({-5.0f, -5.0f, 5.0f, 5.0f, top});
    return t;
}

bool same_bytes(const FootPlacementState& a, const FootPlacementState& b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

bool same_vec(vec3 a, vec3 b) { return std::memcmp(&a, &b, sizeof a) == 0; }
}  // namespace

TEST_CASE("FootPlacementJob: bad inputs fail validate() and run() writes nothing", "[foot_placement][job]") {
    const FootPlacementRig rig = make_foot_placement_rig(kLegParents, kLeftAnkle, kRightAnkle);
    REQUIRE(rig.valid);
    const Terrain flat;
    FootPlacementState state;
    state.body_offset = 0.125f;  // a state the job would change
    const FootPlacementState state_before = state;
    test::SentinelPose out(7);
    FootPlacementJob valid{&state, &rig, &flat, kBothFeetInContact, 0.01f, 0.15f, 10.0f, kLegParents, out.spans()};
    const auto check_refused = [&](const FootPlacementJob& job) {
        CHECK_FALSE(job.validate());
        CHECK_FALSE(job.run());
        CHECK(out.untouched());
        CHECK(same_bytes(state, state_before));
    };
    SECTION("null state, rig or terrain") {
        FootPlacementJob job = valid;
        job.state = nullptr;
        check_refused(job);
        job = valid;
        job.rig = nullptr;
        check_refused(job);
        job = valid;
        job.terrain = nullptr;
        check_refused(job);
    }
    SECTION("a rig without legs, or with joints off the skeleton") {
        FootPlacementRig no_legs = make_foot_placement_rig(kLegParents, kLeftAnkle, 99);
        CHECK_FALSE(no_legs.valid);
        FootPlacementJob job = valid;
        job.rig = &no_legs;
        check_refused(job);
        FootPlacementRig off = rig;
        off.legs[1].ankle = 7;
        job.rig = &off;
        check_refused(job);
        off = rig;
        off.legs[0].hip = -1;
        check_refused(job);
        off = rig;
        off.root = 12;
        check_refused(job);
    }
    SECTION("negative or non-finite time and rates") {
        FootPlacementJob job = valid;
        job.dt = -0.01f;
        check_refused(job);
        job.dt = NAN;
        check_refused(job);
        job = valid;
        job.release_s = -1.0f;
        check_refused(job);
        job = valid;
        job.terrain_rate = 0.0f;
        check_refused(job);
    }
    SECTION("spans not of the skeleton's size") {
        test::SentinelPose short_pose(6);
        FootPlacementJob job = valid;
        for (int span = 0; span < 4; ++span) {
            PoseSpans p = out.spans();
            if (span == 0) p.local_rotations = short_pose.local_rotations;
            if (span == 1) p.local_translations = short_pose.local_translations;
            if (span == 2) p.model_rotations = short_pose.model_rotations;
            if (span == 3) p.model_positions = short_pose.model_positions;
            job.pose = p;
            check_refused(job);
        }
        CHECK(short_pose.untouched());
    }
    SECTION("parents not before their children") {
        const std::vector<int> out_of_order = {kNoParent, 0, 1, 2, 0, 6, 5};
        FootPlacementJob job = valid;
        job.parents = out_of_order;
        check_refused(job);
    }
    SECTION("valid inputs run and start the placement") {
        ClipPose clip;
        FootPlacementJob job = valid;
        job.pose = clip.spans();
        CHECK(job.validate());
        CHECK(job.run());
        CHECK(state.started == 1);
    }
}

TEST_CASE("FootPlacementJob raises the body to the ground and keeps the legs' lengths", "[foot_placement][job]") {
    const FootPlacementRig rig = make_foot_placement_rig(kLegParents, kLeftAnkle, kRightAnkle);
    const Terrain step = raised_ground(0.2f);
    FootPlacementState state;
    ClipPose clip;
    const vec3 clip_left_ankle = clip.model_positions[kLeftAnkle];
    const FootPlacementJob job{&state, &rig, &step, kBothFeetInContact, 0.0f, 0.15f, 10.0f,
                               kLegParents, clip.spans()};
    REQUIRE(job.run());
    CHECK(state.body_offset == Approx(0.2f));
    CHECK(clip.local_translations[0].y == Approx(1.1f));
    CHECK(clip.model_positions[kLeftAnkle].y == Approx(clip_left_ankle.y + 0.2f).margin(1e-4));
    for (const FootPin& foot : state.feet) CHECK(foot.contact == 1);
    CHECK(norm_of(clip.model_positions[2] - clip.model_positions[1]) == Approx(0.45f).margin(1e-5));
    CHECK(norm_of(clip.model_positions[3] - clip.model_positions[2]) == Approx(0.43f).margin(1e-5));
}

TEST_CASE("FootPlacementJob::run never allocates", "[foot_placement][job]") {
    const FootPlacementRig rig = make_foot_placement_rig(kLegParents, kLeftAnkle, kRightAnkle);
    const Terrain step = raised_ground(0.1f);
    FootPlacementState state;
    ClipPose clip;
    const ClipPose original;
    int refused = 0;
    const std::uint64_t before = test::allocation_count();
    for (int tick = 0; tick < 100; ++tick) {
        clip.local_rotations = original.local_rotations;  // same size: no allocation
        clip.local_translations = original.local_translations;
        clip.model_rotations = original.model_rotations;
        clip.model_positions = original.model_positions;
        const FootPlacementJob job{&state, &rig, &step, static_cast<std::uint8_t>(tick / 25 % 2 ? 1 : kBothFeetInContact), 1.0f / 60.0f,
                                   0.15f, 10.0f, kLegParents, clip.spans()};
        if (!job.run()) ++refused;
    }
    CHECK(test::allocation_count() == before);
    CHECK(refused == 0);
}

namespace {
// The lowest point of each foot (ankle, or its tip) minus the ground under it.
float foot_clearance(const FootPlacementRig& rig, const ClipPose& pose, const Terrain& ground, int foot) {
    const FootPlacementLeg& leg = rig.legs[static_cast<size_t>(foot)];
    const vec3 a = pose.model_positions[static_cast<size_t>(leg.ankle)];
    const size_t p = static_cast<size_t>(leg.tip_parent);
    const vec3 tip = pose.model_positions[p] + quat_rotate(pose.model_rotations[p], leg.tip);
    const float ca = a.y - query_ground(ground, a.x, a.z).height;
    const float ct = tip.y - query_ground(ground, tip.x, tip.z).height;
    return ca < ct ? ca : ct;
}
}  // namespace

TEST_CASE("FootPlacementJob: keep_above_ground lifts a foot whose tip is under the ground", "[foot_placement][job]") {
    FootPlacementRig rig = make_foot_placement_rig(kLegParents, kLeftAnkle, kRightAnkle);
    const std::vector<int> site_parents = {kLeftAnkle, kRightAnkle};
    Lcg rng{777u};
    auto next = [&] { return rng.next(); };
    // Generated cases (fixed seed): tips 0–15 cm below and 0–25 cm ahead of the
    // ankle (in metres ×2: the scale is applied), ground from −5 to +5 cm.
    for (int c = 0; c < 200; ++c) {
        const std::vector<vec3> site_offsets = {vec3(0.0f, -0.075f * next(), 0.125f * next()),
                                                vec3(0.0f, -0.075f * next(), 0.125f * next())};
        add_foot_tips(rig, kLegParents, site_parents, site_offsets, 2.0f);
        REQUIRE(rig.legs[0].tip_parent == kLeftAnkle);
        REQUIRE(rig.legs[0].toe == -1);  // the ankle has no child joint here
        const Terrain ground = raised_ground(0.1f * next() - 0.05f);
        for (const bool keep : {false, true}) {
            FootPlacementState state;
            ClipPose pose;
            const ClipPose clip = pose;
            FootPlacementJob job{&state, &rig, &ground, kBothFeetInContact, 0.0f, 0.15f, 10.0f, kLegParents, pose.spans(), keep};
            REQUIRE(job.run());
            // A second tick, advancing.
            pose = clip;
            job.pose = pose.spans();
            job.dt = 1.0f / 240.0f;
            REQUIRE(job.run());
            for (int foot = 0; foot < 2; ++foot) {
                const float clearance = foot_clearance(rig, pose, ground, foot);
                if (keep) {
                    CHECK(clearance >= -1e-4f);
                    // Lifted straight up: the pinned ankle keeps its place on the ground plane, the foot its rotation.
                    const size_t a = static_cast<size_t>(rig.legs[static_cast<size_t>(foot)].ankle);
                    CHECK(pose.model_positions[a].x == Approx(clip.model_positions[a].x).margin(1e-4));
                    CHECK(pose.model_positions[a].z == Approx(clip.model_positions[a].z).margin(1e-4));
                    CHECK(quat_angle_between(pose.model_rotations[a], clip.model_rotations[a]) < 1e-3);
                } else if (c == 0) {
                    INFO("without keep_above_ground the generated first case's tip is below the ground");
                    CHECK(clearance < -1e-3f);
                }
            }
        }
    }
    // A tip joint that is not a joint is refused.
    rig.legs[1].tip_parent = 99;
    FootPlacementState state;
    ClipPose pose;
    const Terrain flat;
    CHECK_FALSE((FootPlacementJob{&state, &rig, &flat, kBothFeetInContact, 0.0f, 0.15f, 10.0f, kLegParents, pose.spans(), true}.validate()));
}

// Matching (smooth_feet) bends the knee toward the thigh's +Z, not toward the
// clip's knee off the hip–ankle midpoint: on a nearly straight clip leg that
// offset points anywhere, and on the retargeted CMU clips it flipped between
// ticks and swung the placed knee about the hip–ankle axis (40,000 °/s).
// Generated cases (fixed seed) across the envelope: thigh pitched −0.5…+0.3 rad,
// the clip's knee bent 0.002–0.02 rad about any horizontal axis, then about the
// opposite one; the left foot's ground raised 5–15 cm so the IK must bend the
// knee. The placed knee must stay put (≤ 3 cm apart; the clip's ankle moves
// ≤ 1.7 cm) and in front of the leg. graph_feet (smooth_feet off) keeps the
// clip's bend, and the same cases must show the swing there.
TEST_CASE("FootPlacementJob: smooth_feet's knee bends toward the thigh however straight the clip's leg", "[foot_placement][job]") {
    const FootPlacementRig rig = make_foot_placement_rig(kLegParents, kLeftAnkle, kRightAnkle);
    Lcg rng{1414u};
    auto next = [&] { return rng.next(); };
    float widest_swing_without = 0.0f;
    for (int c = 0; c < 300; ++c) {
        const float pitch = -0.5f + 0.8f * next(), bend = 0.002f + 0.018f * next(), phi = 6.2831853f * next();
        Terrain ground;
        ground.boxes.push_back({0.0f, -2.0f, 0.3f, 2.0f, 0.05f + 0.1f * next()});
        for (const bool smooth : {true, false}) {
            vec3 knees[2];
            float ahead[2];
            for (int flip = 0; flip < 2; ++flip) {
                ClipPose pose;
                const float angle = phi + (flip ? 3.14159265f : 0.0f);
                pose.local_rotations[1] = quat_axis_angle(vec3(1.0f, 0.0f, 0.0f), pitch);
                pose.local_rotations[2] = quat_axis_angle(vec3(std::cos(angle), 0.0f, std::sin(angle)), bend);
                REQUIRE(LocalToModelJob{kLegParents, {pose.local_rotations, pose.local_translations},
                                        {pose.model_rotations, pose.model_positions}}.run());
                const vec3 thigh_z = quat_rotate(pose.model_rotations[1], vec3(0.0f, 0.0f, 1.0f));
                FootPlacementState state;
                FootPlacementJob job{&state, &rig, &ground, kBothFeetInContact, 0.0f, 0.15f, 10.0f, kLegParents, pose.spans()};
                job.smooth_feet = smooth;
                REQUIRE(job.run());
                knees[flip] = pose.model_positions[2];
                const vec3 off = pose.model_positions[2] - 0.5f * (pose.model_positions[1] + pose.model_positions[3]);
                ahead[flip] = off.x * thigh_z.x + off.y * thigh_z.y + off.z * thigh_z.z;
            }
            const vec3 d = knees[0] - knees[1];
            const float swing = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
            INFO("case " << c << " pitch " << pitch << " bend " << bend << " phi " << phi);
            if (smooth) {
                CHECK(swing <= 0.03f);
                CHECK(ahead[0] > 0.0f);
                CHECK(ahead[1] > 0.0f);
            } else {
                widest_swing_without = swing > widest_swing_without ? swing : widest_swing_without;
            }
        }
    }
    CHECK(widest_swing_without > 0.2f);  // the clip's own bend flips the knee to the other side
}

// smooth_feet's tilt spring (step_tilt_normal), generated across its envelope:
// fixed-seed sequences of ground normals of four kinds — steps (a new normal held
// 1–200 ticks), creases (a flat/slope pair, the foot crossing back and forth,
// single-tick flickers included), noise (a base normal shaken every tick, as on
// a heightfield) and slow sweeps — every normal within 60° of up, at a tick rate
// drawn from the config's envelope (30–2000 Hz), then the last normal held 1 s.
// The spring is linear per component with a non-negative position kernel, so the
// normal it carries stays in the convex hull of the normals it was given, and
// its velocity is at most (2y/e)·max|goal − c| for any c (the L1 norm of its
// velocity kernel y²(1 − yt)e^(−yt) is 2y/e): with every goal within α of an
// axis c, the returned unit normal turns at most (2y/e)·tan α rad/s.
namespace {
struct TiltCase {
    std::vector<vec3> goals;
    float dt = 0.0f;
};

vec3 normal_at(float tilt, float azimuth) {
    return vec3(std::sin(tilt) * std::cos(azimuth), std::cos(tilt), std::sin(tilt) * std::sin(azimuth));
}

double angle_between(vec3 a, vec3 b) {
    const double cx = double(a.y) * b.z - double(a.z) * b.y, cy = double(a.z) * b.x - double(a.x) * b.z,
                 cz = double(a.x) * b.y - double(a.y) * b.x;
    const double dot = double(a.x) * b.x + double(a.y) * b.y + double(a.z) * b.z;
    return std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), dot);
}

TiltCase generate_tilt_case(int kind, const std::function<float()>& next) {
    static constexpr int kRates[] = {30, 60, 120, 240, 480, 1000, 2000};
    TiltCase c;
    const int rate = next() < 0.5f ? kRates[static_cast<int>(next() * 6.999f)] : 30 + static_cast<int>(1970.0f * next());
    c.dt = 1.0f / static_cast<float>(rate);
    const int ticks = static_cast<int>((0.5f + 2.5f * next()) * static_cast<float>(rate));
    const float max_tilt = 1.0471976f;  // 60°
    vec3 held = normal_at(max_tilt * next(), 6.2831853f * next());
    const vec3 other = normal_at(max_tilt * next(), 6.2831853f * next());
    const vec3 base = held;
    int hold = 0;
    bool on_other = false;
    for (int t = 0; t < ticks; ++t) {
        if (kind == 0) {  // steps
            if (hold-- <= 0) held = normal_at(max_tilt * next(), 6.2831853f * next()), hold = static_cast<int>(200.0f * next());
        } else if (kind == 1) {  // a crease crossed back and forth
            if (hold-- <= 0) on_other = !on_other, hold = next() < 0.3f ? 0 : static_cast<int>(100.0f * next());
            held = on_other ? other : base;
        } else if (kind == 2) {  // noise about a base normal, up to 10° every tick
            const vec3 shaken = base + 0.18f * normal_at(1.5707963f * next(), 6.2831853f * next());
            held = shaken / std::sqrt(shaken.x * shaken.x + shaken.y * shaken.y + shaken.z * shaken.z);
            if (angle_between(held, vec3(0.0f, 1.0f, 0.0f)) > max_tilt) held = base;
        } else {  // a slow sweep from base to other
            const float u = static_cast<float>(t) / static_cast<float>(ticks);
            const vec3 mixed = base * (1.0f - u) + other * u;
            held = mixed / std::sqrt(mixed.x * mixed.x + mixed.y * mixed.y + mixed.z * mixed.z);
        }
        c.goals.push_back(held);
    }
    for (int t = 0; t < rate; ++t) c.goals.push_back(held);  // held 1 s: 20 halflives
    return c;
}

// The unit normals the spring returns for a case, started at rest on the first goal.
std::vector<vec3> run_tilt_spring(const TiltCase& c) {
    std::vector<vec3> out;
    vec3 normal = c.goals.front(), velocity(0.0f);
    for (const vec3& goal : c.goals) out.push_back(step_tilt_normal(normal, velocity, goal, c.dt));
    return out;
}

// The bound (rad/s) on the turn rate: (2y/e)·tan α, α the widest angle of a goal
// from the better of two axes (up, the goals' mean direction).
double tilt_turn_bound(const std::vector<vec3>& goals) {
    vec3 sum(0.0f);
    for (const vec3& g : goals) sum += g;
    double alpha = 1e9;
    for (const vec3& axis : {vec3(0.0f, 1.0f, 0.0f), sum}) {
        double widest = 0.0;
        for (const vec3& g : goals) widest = std::max(widest, angle_between(axis, g));
        alpha = std::min(alpha, widest);
    }
    const double y = 2.0 * 0.69314718055994531 / kTiltHalflifeS;
    return 2.0 * y / 2.718281828459045 * std::tan(alpha);
}
}  // namespace

TEST_CASE("step_tilt_normal: generated ground normals, unit, rate-bounded, converging, reproducible", "[foot_placement][tilt]") {
    Lcg rng{2026u};
    const std::function<float()> next = [&] { return rng.next(); };
    double worst_ratio = 0.0, worst_single_step_deg_s = 0.0;
    for (int n = 0; n < 400; ++n) {
        const int kind = n % 4;
        const TiltCase c = generate_tilt_case(kind, next);
        const std::vector<vec3> out = run_tilt_spring(c);
        const double bound = tilt_turn_bound(c.goals);
        INFO("case " << n << " kind " << kind << " dt " << c.dt << " ticks " << c.goals.size() << " bound " << bound);
        double fastest = 0.0;
        float length_error = 0.0f;
        for (size_t t = 0; t < out.size(); ++t) {
            const vec3 v = out[t];
            length_error = std::max(length_error, std::abs(std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z) - 1.0f));
            if (t > 0) fastest = std::max(fastest, angle_between(out[t - 1], v) / c.dt);
        }
        CHECK(length_error <= 1e-6f);
        CHECK(fastest <= bound * 1.01 + 1e-4);
        if (bound > 0.0) worst_ratio = std::max(worst_ratio, fastest / bound);
        // Held 1 s (20 halflives): on the held normal to float precision.
        CHECK(angle_between(out.back(), c.goals.back()) <= 1e-5);
        // Bit-reproducible: the same goals give the same bits.
        const std::vector<vec3> again = run_tilt_spring(c);
        CHECK(std::memcmp(out.data(), again.data(), out.size() * sizeof(vec3)) == 0);
    }
    // A single step of θ from rest (a crease crossed once): ≤ (2y/e)·tan(θ/2);
    // 15° (the default slope) at 240 Hz turns the foot at most ~154 °/s.
    for (int n = 0; n < 100; ++n) {
        TiltCase c;
        c.dt = 1.0f / static_cast<float>(30 + static_cast<int>(1970.0f * next()));
        const float theta = 1.0471976f * next();
        const vec3 from = normal_at(0.5f * next(), 6.2831853f * next());
        vec3 to = normal_at(theta, 6.2831853f * next());
        // `to` turned so that it is θ from `from`: build it in from's frame.
        const vec3 side = std::abs(from.x) < 0.9f ? vec3(1.0f, 0.0f, 0.0f) : vec3(0.0f, 0.0f, 1.0f);
        vec3 u = side - from * (side.x * from.x + side.y * from.y + side.z * from.z);
        u /= std::sqrt(u.x * u.x + u.y * u.y + u.z * u.z);
        to = from * std::cos(theta) + u * std::sin(theta);
        c.goals.assign(1, from);
        c.goals.insert(c.goals.end(), static_cast<size_t>(1.0f / c.dt), to);
        const std::vector<vec3> out = run_tilt_spring(c);
        double fastest = 0.0;
        for (size_t t = 1; t < out.size(); ++t) fastest = std::max(fastest, angle_between(out[t - 1], out[t]) / c.dt);
        const double y = 2.0 * 0.69314718055994531 / kTiltHalflifeS;
        const double bound = 2.0 * y / 2.718281828459045 * std::tan(0.5 * theta);
        INFO("step " << n << " theta " << theta << " dt " << c.dt);
        CHECK(fastest <= bound * 1.01 + 1e-4);
        if (std::abs(theta - 0.2618f) < 0.05f) worst_single_step_deg_s = std::max(worst_single_step_deg_s, fastest * 57.29578);
    }
    // The bound is not loose by orders of magnitude (a snap would read 10–100×).
    CHECK(worst_ratio > 0.2);
    WARN("fastest turn over its bound " << worst_ratio << "; ~15° single steps up to " << worst_single_step_deg_s << " °/s");
}

// Matching (smooth_feet + keep_above_ground) carries free feet over stairs
// without snapping them: the lift looks ahead along the foot's horizontal
// motion, and a foot the lift has not raised in time is held back short of the
// riser instead of jumping up it in one tick (the snap measured 1,527–2,421 °/s
// at the knee on the default stairs). Generated cases (fixed seed) across the
// envelope: three risers 5–25 cm, up or down, treads 22–40 cm, the first 0–60 cm
// ahead; the clip's feet 1–11 cm above its floor with tips 12 cm ahead; the
// clip moving 0.5–5 m/s; 60–1000 Hz. Every tick no point of either foot is
// more than 1 mm under the ground and no ankle moves faster than the clip's
// speed plus twice the stairs' own climb rate (speed × riser / tread) plus
// 4 m/s (a one-tick snap of a 5 cm riser is 12 m/s at 240 Hz, of a 25 cm one
// 60 m/s; at 60 Hz a snap of a low riser is not told from a fast rise); 0.5 s past the stairs the ankles are back
// within 2 mm of the clip's on the ground plane; a second run gives the same bytes.
TEST_CASE("FootPlacementJob: smooth_feet carries free feet over generated stairs without snapping or penetrating",
          "[foot_placement][job]") {
    FootPlacementRig rig = make_foot_placement_rig(kLegParents, kLeftAnkle, kRightAnkle);
    const std::vector<int> site_parents = {kLeftAnkle, kRightAnkle};
    const std::vector<vec3> site_offsets = {vec3(0.0f, -0.05f, 0.12f), vec3(0.0f, -0.05f, 0.12f)};
    add_foot_tips(rig, kLegParents, site_parents, site_offsets, 1.0f);
    Lcg rng{2026u};
    auto next = [&] { return rng.next(); };
    const float rates[] = {60.0f, 120.0f, 144.0f, 240.0f, 500.0f, 1000.0f};
    float fastest_extra = 0.0f, deepest = 0.0f;
    int held_cases = 0;
    for (int c = 0; c < 300; ++c) {
        const float riser = 0.05f + 0.2f * next(), tread = 0.22f + 0.18f * next(), first = 0.6f * next();
        const bool up = next() < 0.5f;
        const float raise = 0.01f + 0.1f * next(), speed = 0.5f + 4.5f * next();
        const float dt = 1.0f / rates[static_cast<size_t>(next() * 5.999f)];
        Terrain stairs;
        for (int i = 0; i < 3; ++i) {
            const float edge = first + tread * static_cast<float>(i);
            if (up) stairs.boxes.push_back({-5.0f, edge, 5.0f, 50.0f, riser * static_cast<float>(i + 1)});
            else stairs.boxes.push_back({-5.0f, -50.0f, 5.0f, edge, riser * static_cast<float>(3 - i)});
        }
        const int ticks = static_cast<int>((first + 3.0f * tread + 0.3f) / speed / dt + 0.5f / dt);
        INFO("case " << c << ": riser " << riser << " tread " << tread << " first " << first << (up ? " up" : " down")
                     << " raise " << raise << " speed " << speed << " dt " << dt);
        std::vector<FootPlacementState> runs(2);
        bool held = false;
        for (int run = 0; run < 2; ++run) {
            FootPlacementState& state = runs[static_cast<size_t>(run)];
            vec3 previous[2];
            for (int t = 0; t <= ticks; ++t) {
                ClipPose pose;
                pose.local_translations[0] += vec3(0.0f, raise, speed * dt * static_cast<float>(t));
                REQUIRE(LocalToModelJob{kLegParents, pose.spans().local(), pose.spans().model()}.run());
                const ClipPose clip = pose;
                FootPlacementJob job{&state, &rig, &stairs, 0, t == 0 ? 0.0f : dt, 0.15f, 10.0f, kLegParents, pose.spans(), true};
                job.smooth_feet = true;
                REQUIRE(job.run());
                for (int foot = 0; foot < 2; ++foot) {
                    const FootPin& pin = state.feet[static_cast<size_t>(foot)];
                    held = held || pin.hold_offset.x != 0.0f || pin.hold_offset.z != 0.0f;
                    const float clearance = foot_clearance(rig, pose, stairs, foot);
                    deepest = std::max(deepest, -clearance);
                    CHECK(clearance >= -1e-3f);
                    const size_t a = static_cast<size_t>(rig.legs[static_cast<size_t>(foot)].ankle);
                    const vec3 ankle = pose.model_positions[a];
                    if (t > 0) {
                        const vec3 d = ankle - previous[foot];
                        const float extra = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z) / dt - speed;
                        fastest_extra = std::max(fastest_extra, extra);
                        CHECK(extra <= 4.0f + 2.0f * speed * riser / tread);
                    }
                    previous[foot] = ankle;
                    if (t == ticks) {
                        CHECK(std::fabs(ankle.x - clip.model_positions[a].x) < 2e-3f);
                        CHECK(std::fabs(ankle.z - clip.model_positions[a].z) < 2e-3f);
                    }
                }
            }
        }
        held_cases += held ? 1 : 0;
        CHECK(same_bytes(runs[0], runs[1]));
    }
    INFO("fastest ankle beyond the clip's " << fastest_extra << " m/s; deepest " << deepest << " m; cases held back " << held_cases);
    CHECK(held_cases > 0);  // the envelope reaches the hold, not only the lift
    WARN("smooth_feet stairs: fastest ankle beyond the clip's " << fastest_extra << " m/s, deepest point " << deepest
                                                              << " m, " << held_cases << " of 300 cases held back");
}

// soften_reach (smooth_feet's soft reach): generated cases (fixed seed) across
// its envelope: hips anywhere within 10 m, targets in any direction at 0–2×
// reach, reach 0.3–2 m, width 0.5–20 % of reach (and ≤ 0). Nearer than
// reach − width (or no width): the target unchanged, bit for bit. Farther: on
// the same ray from the hip, never past reach (far out it rounds to it), never nearer than
// reach − width, increasing with the target's distance, and with a slope of
// ~1 just past reach − width (no kink where the easing starts).
TEST_CASE("soften_reach: generated targets, unchanged inside, eased short of reach outside, monotonic, C1",
          "[foot_placement][soft_reach]") {
    Lcg rng{31337u};
    auto next = [&] { return rng.next(); };
    int eased = 0;
    for (int c = 0; c < 2000; ++c) {
        const vec3 root(20.0f * next() - 10.0f, 20.0f * next() - 10.0f, 20.0f * next() - 10.0f);
        vec3 dir(2.0f * next() - 1.0f, 2.0f * next() - 1.0f, 2.0f * next() - 1.0f);
        const float n = std::sqrt(dir.x * dir.x + dir.y * dir.y + dir.z * dir.z);
        if (n < 1e-3f) continue;
        dir = dir / n;
        const float reach = 0.3f + 1.7f * next(), width = (0.005f + 0.195f * next()) * reach;
        const float d = 2.0f * reach * next();
        const vec3 target = root + dir * d;
        INFO("case " << c << ": reach " << reach << " width " << width << " distance " << d);
        const vec3 out = soften_reach(root, target, reach, width);
        CHECK(same_vec(soften_reach(root, target, reach, 0.0f), target));
        CHECK(same_vec(soften_reach(root, target, reach, -width), target));
        const float start = reach - width;
        if (d <= start) {
            CHECK(same_vec(out, target));
            continue;
        }
        ++eased;
        const float got = distance_of(root, out);
        CHECK(got <= reach + 2e-5f);  // short of reach; far out it rounds to it (hips 10 m out: ulps of 1e-6 m)
        CHECK(got >= start - 1e-4f * reach);
        const vec3 along = (out - root) / got;  // the same ray
        CHECK(along.x * dir.x + along.y * dir.y + along.z * dir.z > 1.0f - 1e-5f);
        // Increasing: a target 1 mm farther is eased at least as far.
        CHECK(distance_of(root, soften_reach(root, root + dir * (d + 1e-3f), reach, width)) >= got - 1e-5f);
    }
    CHECK(eased > 500);
    // No kink at start: the slope just past it is ~1, and far out it flattens.
    const vec3 root(0.0f), dir(0.0f, -1.0f, 0.0f);
    for (const float width : {0.01f, 0.03f, 0.1f}) {
        const float reach = 0.9f, start = reach - width, step = 1e-3f * width;
        const float just_past = distance_of(root, soften_reach(root, dir * (start + step), reach, width));
        CHECK((just_past - start) / step == Approx(1.0).margin(0.01));
        const float far = distance_of(root, soften_reach(root, dir * (reach + 10.0f * width), reach, width));
        CHECK(far > reach - 0.02f * width);
        CHECK(far < reach);
    }
}

// pinned_reach_target (smooth_feet's pinned reach): generated cases (fixed seed)
// across its envelope: hips anywhere within 10 m, targets in any direction at
// 0–1.5× reach, reach 0.3–2 m, width 0 or 0.5–20 % of reach, the IK's soft start
// 0.9–1. The aim, softened (soften_reach) and solved by the real two-bone IK,
// puts the ankle on the target within 0.02 mm wherever the target lies within
// kPinExactReachFraction of the softened range (the pin held exactly); farther,
// on the same ray, increasing with the target's distance (no jump at the edge).
TEST_CASE("pinned_reach_target: generated pins, the softened IK lands on them exactly, continuous beyond",
          "[foot_placement][soft_reach]") {
    Lcg rng{4242u};
    auto next = [&] { return rng.next(); };
    auto ankle_for = [](vec3 root, vec3 target, float reach, float width, float soft_start) {
        TwoBoneIkJob ik;
        ik.root = root;
        ik.target = soften_reach(root, pinned_reach_target(root, target, reach, width, soft_start), reach, width);
        ik.upper_length = ik.lower_length = 0.5f * reach;
        ik.soft_reach_start = soft_start;
        TwoBoneIkResult r;
        ik.result = &r;
        REQUIRE(ik.run());
        return r.end;
    };
    int exact = 0, beyond = 0;
    for (int c = 0; c < 3000; ++c) {
        const vec3 root(20.0f * next() - 10.0f, 20.0f * next() - 10.0f, 20.0f * next() - 10.0f);
        vec3 dir(2.0f * next() - 1.0f, 2.0f * next() - 1.0f, 2.0f * next() - 1.0f);
        const float n = norm_of(dir);
        if (n < 1e-3f) continue;
        dir = dir / n;
        const float reach = 0.3f + 1.7f * next();
        const float width = c % 4 == 0 ? 0.0f : (0.005f + 0.195f * next()) * reach;
        const float soft_start = 0.9f + 0.1f * next();
        const float d = 1.5f * reach * next();
        const vec3 target = root + dir * d;
        INFO("case " << c << ": reach " << reach << " width " << width << " soft start " << soft_start << " distance " << d);
        const vec3 ankle = ankle_for(root, target, reach, width, soft_start);
        const float top = width > 0.0f ? reach * (soft_start + 0.5f * (1.0f - soft_start)) : reach;
        const float got = norm_of(ankle - root);
        if (d <= kPinExactReachFraction * top) {
            ++exact;
            CHECK(norm_of(ankle - target) <= 2e-5f);
        } else {
            ++beyond;
            const vec3 along = (ankle - root) / got;
            CHECK(along.x * dir.x + along.y * dir.y + along.z * dir.z > 1.0f - 1e-5f);
            CHECK(got <= reach + 2e-5f);
        }
        // Increasing, and continuous: 0.1 mm farther moves the ankle out by 0 to 0.1 mm.
        const float farther = norm_of(ankle_for(root, root + dir * (d + 1e-4f), reach, width, soft_start) - root);
        CHECK(farther >= got - 1e-5f);
        CHECK(farther <= got + 1e-4f + 2e-5f);
    }
    CHECK(exact > 1000);
    CHECK(beyond > 300);
}

// reach_drop_needed (smooth_feet's lowering for reach): generated cases (fixed
// seed) across its envelope: hips anywhere within 10 m, targets in any
// direction at 0–2× reach, reach 0.3–2 m, cap 0–60 % of reach. Always in [0, cap];
// 0 when the target is within reach. Where a drop within the cap reaches it,
// the hip lowered by the answer has the target on the reach sphere and lowered
// by 1 mm less does not reach it (the least drop, not merely one); where none
// does, the answer brings the target nearest (1 mm more or less is no nearer).
TEST_CASE("reach_drop_needed: generated hips and targets, the least drop that reaches, capped", "[foot_placement][reach_drop]") {
    Lcg rng{4242u};
    auto next = [&] { return rng.next(); };
    int reached = 0, nearest = 0;
    for (int c = 0; c < 3000; ++c) {
        const vec3 hip(20.0f * next() - 10.0f, 20.0f * next() - 10.0f, 20.0f * next() - 10.0f);
        vec3 dir(2.0f * next() - 1.0f, 2.0f * next() - 1.0f, 2.0f * next() - 1.0f);
        const float n = std::sqrt(dir.x * dir.x + dir.y * dir.y + dir.z * dir.z);
        if (n < 1e-3f) continue;
        dir = dir / n;
        const float reach = 0.3f + 1.7f * next(), cap = 0.6f * reach * next();
        // Every other case just past reach and below the hip, as a pinned ankle is.
        if (c % 2) dir.y = -std::fabs(dir.y);
        const vec3 target = hip + dir * ((c % 2 ? 0.9f + 0.3f * next() : 2.0f * next()) * reach);
        INFO("case " << c << ": reach " << reach << " cap " << cap << " distance " << distance_of(hip, target) << " dir.y " << dir.y);
        const float drop = reach_drop_needed(hip, target, reach, cap);
        REQUIRE(drop >= 0.0f);
        REQUIRE(drop <= cap);
        if (distance_of(hip, target) <= reach * (1.0f - 1e-5f)) {
            CHECK(drop == 0.0f);
            continue;
        }
        const vec3 lowered = hip - vec3(0.0f, drop, 0.0f);
        const float at = distance_of(lowered, target);
        if (at <= reach * (1.0f + 1e-4f)) {
            ++reached;
            CHECK(at >= reach * (1.0f - 1e-4f));
            if (drop > 1e-3f) CHECK(distance_of(lowered + vec3(0.0f, 1e-3f, 0.0f), target) > reach);
        } else {
            ++nearest;
            if (drop + 1e-3f <= cap) CHECK(distance_of(lowered - vec3(0.0f, 1e-3f, 0.0f), target) >= at * (1.0f - 1e-6f));
            if (drop >= 1e-3f) CHECK(distance_of(lowered + vec3(0.0f, 1e-3f, 0.0f), target) >= at * (1.0f - 1e-6f));
        }
    }
    INFO(reached << " reached, " << nearest << " as near as it gets");
    CHECK(reached > 500);
    CHECK(nearest > 500);
    CHECK(reach_drop_needed(vec3(0.0f), vec3(0.0f, -1.0f, 0.0f), 0.0f, 0.1f) == 0.1f);  // no leg: hip to target's level, capped
}

// smooth_feet lowers the body for a pinned foot the clip's body walks away
// from (the retargeted CMU stop: the heel lifts while the hip moves on):
// nearly straight legs, both feet in contact, the clip's pelvis sliding
// forward at 0.3 m/s (slow enough to stay pinned) for 0.8 s (0.24 m, under
// the 0.25 m slip limit) at 240 Hz. With smooth_feet the ankles stay on their
// pins (< 0.5 mm) and the body comes down by at most kMaxReachDropM, a little
// per tick; graph_feet (no lowering) drags them. Then the clip lifts the feet
// and the body rises back.
TEST_CASE("FootPlacementJob: smooth_feet lowers the body so a pinned foot stays in reach", "[foot_placement][job][reach_drop]") {
    const FootPlacementRig rig = make_foot_placement_rig(kLegParents, kLeftAnkle, kRightAnkle);
    const Terrain flat = raised_ground(0.0f);
    const float dt = 1.0f / 240.0f;
    float worst_slide[2] = {0.0f, 0.0f};
    for (const bool smooth : {true, false}) {
        FootPlacementState state;
        vec3 pins[2];
        float previous_drop = 0.0f, fastest_drop = 0.0f;
        for (int t = 0; t <= 432; ++t) {  // 0.8 s pinned, then 1 s lifted
            const bool pinned = t <= 192;
            ClipPose pose;
            for (const int hip : {1, 4}) {
                pose.local_rotations[static_cast<size_t>(hip)] = quat_axis_angle(vec3(1.0f, 0.0f, 0.0f), -0.1);
                pose.local_rotations[static_cast<size_t>(hip) + 1] = quat_axis_angle(vec3(1.0f, 0.0f, 0.0f), 0.2);
            }
            pose.local_translations[0].z = 0.3f * dt * static_cast<float>(pinned ? t : 192);
            REQUIRE(LocalToModelJob{kLegParents, pose.spans().local(), pose.spans().model()}.run());
            FootPlacementJob job{&state, &rig, &flat, pinned ? kBothFeetInContact : std::uint8_t{0}, t == 0 ? 0.0f : dt,
                                 0.15f, 10.0f, kLegParents, pose.spans()};
            job.smooth_feet = smooth;
            REQUIRE(job.run());
            CHECK(state.reach_drop >= 0.0f);
            CHECK(state.reach_drop <= kMaxReachDropM);
            if (t > 0) fastest_drop = std::max(fastest_drop, std::fabs(state.reach_drop - previous_drop) / dt);
            previous_drop = state.reach_drop;
            for (int foot = 0; foot < 2; ++foot) {
                const vec3 ankle = pose.model_positions[static_cast<size_t>(rig.legs[static_cast<size_t>(foot)].ankle)];
                if (t == 0) pins[foot] = ankle;
                if (pinned) {
                    REQUIRE(state.feet[static_cast<size_t>(foot)].contact == 1);
                    const vec3 d = ankle - pins[foot];
                    worst_slide[smooth ? 0 : 1] = std::max(worst_slide[smooth ? 0 : 1], std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z));
                }
            }
            if (smooth && t == 192) CHECK(state.reach_drop > 0.01f);  // the legs needed it
        }
        if (smooth) {
            INFO("fastest the body came down or rose: " << fastest_drop << " m/s");
            CHECK(fastest_drop < 0.5f);
            CHECK(state.reach_drop < 1e-3f);  // risen back within the second after the lift
        } else {
            CHECK(state.reach_drop == 0.0f);  // graph_feet never lowers
        }
    }
    INFO("pinned ankles moved up to " << worst_slide[0] * 1000.0f << " mm (smooth_feet), " << worst_slide[1] * 1000.0f
                                      << " mm (graph_feet)");
    CHECK(worst_slide[0] < 5e-4f);
    CHECK(worst_slide[1] > 5e-3f);
}
