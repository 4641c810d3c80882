// CPU-side meshes and pure helpers of the renderer: capsule skinning data, terrain
// geometry, interpolation and the follow camera. No GL context needed.
#include <catch2/catch.hpp>

#include <cmath>

#include "render_es/camera.hpp"
#include "render_es/interpolate.hpp"
#include "render_es/mesh.hpp"
#include "runtime/gait/puppet.hpp"

using namespace marionette;
using namespace marionette::render;

namespace {
vec3 to_vec(const std::array<float, 3>& a) { return vec3(a[0], a[1], a[2]); }
float distance_to_segment(vec3 p, vec3 a, vec3 b) {
    const vec3 ab = b - a;
    const float t = std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0f, 1.0f);
    return glm::length(p - (a + ab * t));
}
}  // namespace

TEST_CASE("capsule mesh of the default puppet: valid weights, joints and indices", "[render][mesh]") {
    const Skeleton skeleton = make_puppet_skeleton(SimConfig{});
    const SkinnedMesh mesh = make_capsule_mesh(skeleton);
    REQUIRE(mesh.inverse_bind.size() == static_cast<size_t>(skeleton.joint_count()));
    REQUIRE(!mesh.vertices.empty());
    REQUIRE(mesh.indices.size() % 3 == 0);
    for (std::uint16_t i : mesh.indices) REQUIRE(i < mesh.vertices.size());
    bool blended = false;
    for (const SkinnedVertex& v : mesh.vertices) {
        float sum = 0.0f;
        for (int k = 0; k < 4; ++k) {
            REQUIRE(v.joints[static_cast<size_t>(k)] < skeleton.joint_count());
            REQUIRE(v.weights[static_cast<size_t>(k)] >= 0.0f);
            sum += v.weights[static_cast<size_t>(k)];
        }
        REQUIRE(sum == Approx(1.0f).margin(1e-5));
        REQUIRE(glm::length(to_vec(v.normal)) == Approx(1.0f).margin(1e-4));
        if (v.weights[0] < 0.99f) blended = true;
        REQUIRE(v.part <= 2);
    }
    CHECK(blended);  // joints bend smoothly: some vertices follow two bones
}

TEST_CASE("capsules wrap their bones: every shin vertex lies at the shin radius from the knee-ankle segment", "[render][mesh]") {
    const SimConfig config;
    const Skeleton skeleton = make_puppet_skeleton(config);
    const SkinnedMesh mesh = make_capsule_mesh(skeleton);
    // Rest model positions from the inverse bind matrices (their translation is −R⁻¹p).
    auto rest_position = [&](int j) {
        const auto& m = mesh.inverse_bind[static_cast<size_t>(j)];
        const glm::mat3 r_inv(m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]);
        return -glm::transpose(r_inv) * vec3(m[12], m[13], m[14]);
    };
    const vec3 knee = rest_position(kShinL);
    const vec3 ankle = rest_position(kFootL);
    CHECK(knee.y - ankle.y == Approx(config.shin_length).margin(1e-4));
    int shin_vertices = 0;
    for (const SkinnedVertex& v : mesh.vertices) {
        if (v.joints[0] != kShinL) continue;
        ++shin_vertices;
        CHECK(distance_to_segment(to_vec(v.position), knee, ankle) ==
              Approx(capsule_radius("shin_l", config.shin_length)).margin(1e-4));
        CHECK(v.part == static_cast<std::uint8_t>(BodyPart::left));
    }
    CHECK(shin_vertices > 0);
}

TEST_CASE("terrain mesh: flat ground, box tops up and walls outward, slopes follow their grade", "[render][mesh]") {
    Terrain terrain;
    terrain.boxes.push_back({1.0f, 2.0f, 3.0f, 3.0f, 0.2f});
    terrain.slopes.push_back({-2.0f, 0.0f, -1.0f, 4.0f, 0.0f, 0.0f, 0.25f});
    const TerrainMesh mesh = make_terrain_mesh(terrain, 10.0f);
    // ground quad + box (top + 4 walls) + slope (top + 4 walls), 4 vertices each
    REQUIRE(mesh.vertices.size() == 4u * 11u);
    REQUIRE(mesh.indices.size() == 6u * 11u);
    int box_tops = 0;
    for (const TerrainVertex& v : mesh.vertices) {
        const vec3 p = to_vec(v.position);
        const vec3 n = to_vec(v.normal);
        if (v.part == static_cast<float>(TerrainPart::box)) {
            const vec3 centre(2.0f, 0.1f, 2.5f);
            if (n.y > 0.5f) {
                ++box_tops;
                CHECK(p.y == Approx(0.2f));
            } else {
                CHECK(n.y == Approx(0.0f).margin(1e-6));
                CHECK(glm::dot(n, p - centre) > 0.0f);  // faces away from the box
            }
        }
        if (v.part == static_cast<float>(TerrainPart::slope) && n.y > 0.5f) {
            CHECK(p.y == Approx(0.25f * (p.z - 0.0f)).margin(1e-5));
            CHECK(n.z == Approx(-0.25f / std::sqrt(1.0f + 0.0625f)).margin(1e-5));
        }
    }
    CHECK(box_tops == 4);
}

TEST_CASE("heightfield terrain becomes a grid whose normals follow its gradient", "[render][mesh]") {
    Terrain terrain;
    terrain.heightfield = {0.0f, 0.0f, 0.5f, 3, 2, {0.0f, 0.1f, 0.2f, 0.0f, 0.1f, 0.2f}};  // rises 0.2 per metre in x
    const TerrainMesh mesh = make_terrain_mesh(terrain);
    REQUIRE(mesh.vertices.size() == 6u);
    REQUIRE(mesh.indices.size() == 2u * 2u * 3u);
    for (const TerrainVertex& v : mesh.vertices) CHECK(v.normal[0] == Approx(-0.2f / std::sqrt(1.04f)).margin(1e-5));
}

TEST_CASE("interpolation: alpha 0 and 1 give the ticks, positions lerp, rotations slerp, heading wraps", "[render][interpolate]") {
    PuppetState a;
    PuppetState b;
    a.joint_count = b.joint_count = 2;
    a.tick = 10;
    b.tick = 11;
    a.root_position = vec3(0.0f, 0.0f, 1.0f);
    b.root_position = vec3(1.0f, 0.0f, 3.0f);
    a.model_positions[1] = vec3(0.0f);
    b.model_positions[1] = vec3(2.0f, 4.0f, 0.0f);
    a.model_rotations[1] = quat_identity();
    b.model_rotations[1] = quat_axis_angle(vec3(0, 1, 0), 1.0);
    a.heading = 3.0f;
    b.heading = -3.0f;  // 0.28 rad apart across ±π
    PuppetState out;
    interpolate_state(a, b, 0.0f, out);
    CHECK(out.root_position == a.root_position);
    CHECK(out.model_rotations[1] == a.model_rotations[1]);
    interpolate_state(a, b, 1.0f, out);
    CHECK(out.root_position == b.root_position);
    CHECK(out.tick == 11);
    interpolate_state(a, b, 0.5f, out);
    CHECK(out.root_position.x == Approx(0.5f));
    CHECK(out.root_position.z == Approx(2.0f));
    CHECK(out.model_positions[1].y == Approx(2.0f));
    CHECK(quat_angle_between(out.model_rotations[1], quat_identity()) == Approx(0.5).margin(1e-5));
    CHECK(std::fabs(out.heading) > 3.1f);  // through π, not through 0
    interpolate_state(a, b, 7.0f, out);    // clamped
    CHECK(out.root_position == b.root_position);
}

TEST_CASE("extrapolation carries the newest tick on along the last tick's motion, at most one tick", "[render][interpolate]") {
    PuppetState a;
    PuppetState b;
    a.joint_count = b.joint_count = 2;
    a.tick = 10;
    b.tick = 11;
    a.root_position = vec3(0.0f, 0.0f, 1.0f);
    b.root_position = vec3(1.0f, 0.0f, 3.0f);
    a.model_rotations[1] = quat_identity();
    b.model_rotations[1] = quat_axis_angle(vec3(0, 1, 0), 0.4);
    a.heading = 3.0f;
    b.heading = -3.0f;  // 0.28 rad apart across ±π
    PuppetState out;
    extrapolate_state(a, b, 0.0f, out);
    CHECK(out.root_position == b.root_position);
    CHECK(out.tick == 11);
    extrapolate_state(a, b, 0.5f, out);
    CHECK(out.root_position.x == Approx(1.5f));
    CHECK(out.root_position.z == Approx(4.0f));
    CHECK(quat_angle_between(out.model_rotations[1], quat_identity()) == Approx(0.6).margin(1e-5));
    // Half a tick on along the short arc (0.28 rad per tick), as an angle.
    const double expected_heading = -3.0 + 0.5 * (2.0 * 3.14159265358979 - 6.0);
    CHECK(std::remainder(out.heading - expected_heading, 2.0 * 3.14159265358979) == Approx(0.0).margin(1e-5));
    extrapolate_state(a, b, 7.0f, out);    // clamped to one tick ahead
    CHECK(out.root_position.x == Approx(2.0f));
    extrapolate_state(a, b, -1.0f, out);   // never behind the newest tick
    CHECK(out.root_position == b.root_position);
}

TEST_CASE("follow camera snaps first, then eases toward the puppet with its time constant", "[render][camera]") {
    CameraSettings s;
    s.smoothing_s = 0.5f;
    s.target_height_m = 1.0f;
    FollowCamera camera;
    follow(camera, vec3(0.0f), 1.0f / 60.0f, s);
    CHECK(camera.target == vec3(0.0f, 1.0f, 0.0f));
    follow(camera, vec3(2.0f, 0.0f, 0.0f), 0.5f, s);  // one time constant: 1 − 1/e of the way
    CHECK(camera.target.x == Approx(2.0f * (1.0f - std::exp(-1.0f))).margin(1e-5));
    for (int i = 0; i < 600; ++i) follow(camera, vec3(2.0f, 0.0f, 0.0f), 1.0f / 60.0f, s);
    CHECK(camera.target.x == Approx(2.0f).margin(1e-4));
    const vec3 eye = camera_eye(camera, s);
    CHECK(std::hypot(eye.x - camera.target.x, eye.z - camera.target.z) == Approx(s.distance_m));
    CHECK(eye.y - camera.target.y == Approx(s.height_m));
}
