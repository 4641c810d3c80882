#include "render_es/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace marionette::render {

namespace {
struct RadiusRule {
    const char* prefix;
    float radius;
};
// The default puppet (runtime/gait/puppet.cpp): radii in metres of the bone each joint drives.
constexpr RadiusRule kRadii[] = {
    {"pelvis", 0.11f},   {"spine_01", 0.12f}, {"spine_02", 0.13f}, {"spine_03", 0.13f},
    {"neck", 0.05f},     {"head", 0.10f},     {"clavicle", 0.05f}, {"upperarm", 0.052f},
    {"forearm", 0.042f}, {"hand", 0.035f},    {"thigh", 0.078f},   {"shin", 0.058f},
    {"foot", 0.045f},    {"toe", 0.035f},
};

BodyPart part_of(const std::string& name) {
    if (name.size() > 2 && name.compare(name.size() - 2, 2, "_l") == 0) return BodyPart::left;
    if (name.size() > 2 && name.compare(name.size() - 2, 2, "_r") == 0) return BodyPart::right;
    return BodyPart::body;
}

float smoothstep(float edge0, float edge1, float x) {
    const float t = std::clamp((x - edge0) / (edge1 - edge0), 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
}

// Column-major 4×4 of the rigid transform (rotation q, translation p), inverted.
std::array<float, 16> inverse_rigid(quat q, vec3 p) {
    const quat qi = quat_conjugate(q);
    const vec3 x = quat_rotate(qi, vec3(1, 0, 0));
    const vec3 y = quat_rotate(qi, vec3(0, 1, 0));
    const vec3 z = quat_rotate(qi, vec3(0, 0, 1));
    const vec3 t = -quat_rotate(qi, p);
    return {x.x, x.y, x.z, 0, y.x, y.y, y.z, 0, z.x, z.y, z.z, 0, t.x, t.y, t.z, 1};
}

struct Bone {
    int joint;         // drives it
    int parent_joint;  // kNoParent at the root
    int child_joint;   // -1 for an end site
    vec3 start;
    vec3 end;
};

void add_capsule(SkinnedMesh& mesh, const Bone& bone, float radius, BodyPart part, const CapsuleMeshSettings& s) {
    const vec3 axis_full = bone.end - bone.start;
    const float length = std::sqrt(axis_full.x * axis_full.x + axis_full.y * axis_full.y + axis_full.z * axis_full.z);
    const vec3 axis = axis_full / length;
    // Any unit vector not parallel to the axis gives the ring's frame.
    const vec3 helper = std::fabs(axis.y) < 0.9f ? vec3(0, 1, 0) : vec3(1, 0, 0);
    vec3 u = glm::cross(axis, helper);
    u /= std::sqrt(glm::dot(u, u));
    const vec3 v = glm::cross(axis, u);

    // Rings from the start pole to the end pole: axial offset, ring radius, axial normal part.
    struct Ring {
        float along;
        float ring_radius;
        float normal_axial;
    };
    std::vector<Ring> rings;
    const float half_pi = 1.57079632679f;
    for (int i = 0; i <= s.cap_rings; ++i) {  // start hemisphere, pole first
        const float a = -half_pi + half_pi * static_cast<float>(i) / static_cast<float>(s.cap_rings);
        rings.push_back({radius * std::sin(a), radius * std::cos(a), std::sin(a)});
    }
    for (int i = 1; i < s.body_rings; ++i)
        rings.push_back({length * static_cast<float>(i) / static_cast<float>(s.body_rings), radius, 0.0f});
    for (int i = 0; i <= s.cap_rings; ++i) {  // end hemisphere, equator first
        const float a = half_pi * static_cast<float>(i) / static_cast<float>(s.cap_rings);
        rings.push_back({length + radius * std::sin(a), radius * std::cos(a), std::sin(a)});
    }

    const size_t first = mesh.vertices.size();
    for (const Ring& ring : rings) {
        const float t = std::clamp(ring.along / length, 0.0f, 1.0f);
        // Driven by bone.joint; near the far end blend toward the child joint, near
        // the start toward the parent, meeting at 50/50 on the joint itself.
        float w_child = bone.child_joint >= 0 ? 0.5f * smoothstep(0.65f, 1.0f, t) : 0.0f;
        float w_parent = bone.parent_joint >= 0 ? 0.5f * smoothstep(0.35f, 0.0f, t) : 0.0f;
        const float w_self = 1.0f - w_child - w_parent;
        for (int k = 0; k < s.sides; ++k) {
            const float angle = 2.0f * 3.14159265358979f * static_cast<float>(k) / static_cast<float>(s.sides);
            const vec3 radial = u * std::cos(angle) + v * std::sin(angle);
            const float radial_scale = std::sqrt(std::max(0.0f, 1.0f - ring.normal_axial * ring.normal_axial));
            const vec3 normal = radial * radial_scale + axis * ring.normal_axial;
            const vec3 p = bone.start + axis * ring.along + radial * ring.ring_radius;
            SkinnedVertex vertex;
            vertex.position = {p.x, p.y, p.z};
            vertex.normal = {normal.x, normal.y, normal.z};
            vertex.joints = {static_cast<std::uint8_t>(bone.joint),
                             static_cast<std::uint8_t>(bone.child_joint >= 0 ? bone.child_joint : bone.joint),
                             static_cast<std::uint8_t>(bone.parent_joint >= 0 ? bone.parent_joint : bone.joint), 0};
            vertex.weights = {w_self, w_child, w_parent, 0.0f};
            vertex.part = static_cast<std::uint8_t>(part);
            mesh.vertices.push_back(vertex);
        }
    }
    const size_t ring_count = rings.size();
    const size_t sides = static_cast<size_t>(s.sides);
    if (mesh.vertices.size() > 65535) throw std::invalid_argument("capsule mesh exceeds 65535 vertices");
    for (size_t r = 0; r + 1 < ring_count; ++r) {
        for (size_t k = 0; k < sides; ++k) {
            const size_t k1 = (k + 1) % sides;
            const auto a = static_cast<std::uint16_t>(first + r * sides + k);
            const auto b = static_cast<std::uint16_t>(first + r * sides + k1);
            const auto c = static_cast<std::uint16_t>(first + (r + 1) * sides + k);
            const auto d = static_cast<std::uint16_t>(first + (r + 1) * sides + k1);
            // Counter-clockwise seen from outside: rings advance along +axis, k turns u→v.
            mesh.indices.insert(mesh.indices.end(), {a, b, d, a, d, c});
        }
    }
}
}  // namespace

float capsule_radius(const std::string& name, float bone_length) {
    for (const RadiusRule& rule : kRadii)
        if (name.rfind(rule.prefix, 0) == 0) return rule.radius;
    return std::clamp(0.15f * bone_length, 0.02f, 0.08f);
}

SkinnedMesh make_capsule_mesh(const Skeleton& skeleton, const CapsuleMeshSettings& settings) {
    const int n = skeleton.joint_count();
    if (n > kMaxBones)
        throw std::invalid_argument("skeleton has " + std::to_string(n) + " joints; the renderer skins at most " +
                                    std::to_string(kMaxBones));
    const Pose rest = rest_pose(skeleton);
    std::vector<quat> model_rotations(static_cast<size_t>(n));
    std::vector<vec3> model_positions(static_cast<size_t>(n));
    const LocalToModelJob fk{skeleton.parents, {rest.local_rotations, rest.local_translations},
                             {model_rotations, model_positions}};
    if (!fk.run()) throw std::invalid_argument("skeleton is not in topological order");

    SkinnedMesh mesh;
    for (int j = 0; j < n; ++j)
        mesh.inverse_bind.push_back(inverse_rigid(model_rotations[static_cast<size_t>(j)], model_positions[static_cast<size_t>(j)]));

    std::vector<Bone> bones;
    for (int c = 0; c < n; ++c) {
        const int p = skeleton.parents[static_cast<size_t>(c)];
        if (p == kNoParent) continue;
        bones.push_back({p, skeleton.parents[static_cast<size_t>(p)], c, model_positions[static_cast<size_t>(p)],
                         model_positions[static_cast<size_t>(c)]});
    }
    for (size_t e = 0; e < skeleton.end_site_parents.size(); ++e) {
        const int p = skeleton.end_site_parents[e];
        const vec3 end = model_positions[static_cast<size_t>(p)] +
                         quat_rotate(model_rotations[static_cast<size_t>(p)], skeleton.end_site_offsets[e]);
        bones.push_back({p, skeleton.parents[static_cast<size_t>(p)], -1, model_positions[static_cast<size_t>(p)], end});
    }
    for (const Bone& bone : bones) {
        const vec3 d = bone.end - bone.start;
        const float length = std::sqrt(glm::dot(d, d));
        if (length < 0.01f) continue;  // too short to draw; the neighbours cover it
        const std::string& name = skeleton.joint_names[static_cast<size_t>(bone.joint)];
        add_capsule(mesh, bone, std::min(capsule_radius(name, length), 0.5f * length + 0.02f), part_of(name), settings);
    }
    return mesh;
}

namespace {
void add_quad(TerrainMesh& mesh, vec3 a, vec3 b, vec3 c, vec3 d, TerrainPart part) {
    // a b c d counter-clockwise seen from the side the normal points to.
    vec3 normal = glm::cross(b - a, d - a);
    const float len = std::sqrt(glm::dot(normal, normal));
    if (len > 0.0f) normal /= len;
    const auto first = static_cast<std::uint32_t>(mesh.vertices.size());
    for (const vec3& p : {a, b, c, d})
        mesh.vertices.push_back({{p.x, p.y, p.z}, {normal.x, normal.y, normal.z}, static_cast<float>(part)});
    mesh.indices.insert(mesh.indices.end(), {first, first + 1, first + 2, first, first + 2, first + 3});
}

// Four side walls of the footprint from `bottom` up to top(x, z).
template <class Top>
void add_walls(TerrainMesh& mesh, float x0, float z0, float x1, float z1, float bottom, Top top, TerrainPart part) {
    const vec3 corners[4] = {{x0, 0, z0}, {x1, 0, z0}, {x1, 0, z1}, {x0, 0, z1}};
    for (int i = 0; i < 4; ++i) {
        // Walk the footprint clockwise seen from above so each wall faces outwards.
        const vec3 p = corners[(i + 1) % 4];
        const vec3 q = corners[i];
        add_quad(mesh, vec3(p.x, bottom, p.z), vec3(q.x, bottom, q.z), vec3(q.x, top(q.x, q.z), q.z),
                 vec3(p.x, top(p.x, p.z), p.z), part);
    }
}
}  // namespace

TerrainMesh make_terrain_mesh(const Terrain& terrain, float extent) {
    TerrainMesh mesh;
    const Heightfield& hf = terrain.heightfield;
    float lowest = 0.0f;
    if (hf.nx >= 2 && hf.nz >= 2 && hf.heights.size() == static_cast<size_t>(hf.nx) * static_cast<size_t>(hf.nz)) {
        const auto first = static_cast<std::uint32_t>(mesh.vertices.size());
        for (std::int32_t iz = 0; iz < hf.nz; ++iz) {
            for (std::int32_t ix = 0; ix < hf.nx; ++ix) {
                const float x = hf.origin_x + static_cast<float>(ix) * hf.cell;
                const float z = hf.origin_z + static_cast<float>(iz) * hf.cell;
                const float h = hf.heights[static_cast<size_t>(iz) * static_cast<size_t>(hf.nx) + static_cast<size_t>(ix)];
                lowest = std::min(lowest, h);
                // Normal from central differences of the grid (one-sided at the edges).
                auto at = [&](std::int32_t i, std::int32_t k) {
                    i = std::clamp(i, 0, hf.nx - 1);
                    k = std::clamp(k, 0, hf.nz - 1);
                    return hf.heights[static_cast<size_t>(k) * static_cast<size_t>(hf.nx) + static_cast<size_t>(i)];
                };
                const float dx = (at(ix + 1, iz) - at(ix - 1, iz)) / (static_cast<float>(std::min(ix + 1, hf.nx - 1) - std::max(ix - 1, 0)) * hf.cell);
                const float dz = (at(ix, iz + 1) - at(ix, iz - 1)) / (static_cast<float>(std::min(iz + 1, hf.nz - 1) - std::max(iz - 1, 0)) * hf.cell);
                vec3 normal(-dx, 1.0f, -dz);
                normal /= std::sqrt(glm::dot(normal, normal));
                mesh.vertices.push_back({{x, h, z}, {normal.x, normal.y, normal.z}, 0.0f});
            }
        }
        const auto nx = static_cast<std::uint32_t>(hf.nx);
        for (std::uint32_t iz = 0; iz + 1 < static_cast<std::uint32_t>(hf.nz); ++iz)
            for (std::uint32_t ix = 0; ix + 1 < nx; ++ix) {
                const std::uint32_t a = first + iz * nx + ix;
                const std::uint32_t b = a + 1;
                const std::uint32_t c = a + nx;
                const std::uint32_t d = c + 1;
                mesh.indices.insert(mesh.indices.end(), {a, c, d, a, d, b});  // upward-facing
            }
    } else {
        add_quad(mesh, vec3(-extent, 0, -extent), vec3(-extent, 0, extent), vec3(extent, 0, extent),
                 vec3(extent, 0, -extent), TerrainPart::ground);
    }
    const float bottom = lowest - 0.05f;  // walls start a little below the ground so no gap shows
    for (const TerrainBox& b : terrain.boxes) {
        add_quad(mesh, vec3(b.min_x, b.top, b.min_z), vec3(b.min_x, b.top, b.max_z), vec3(b.max_x, b.top, b.max_z),
                 vec3(b.max_x, b.top, b.min_z), TerrainPart::box);
        add_walls(mesh, b.min_x, b.min_z, b.max_x, b.max_z, bottom, [&](float, float) { return b.top; }, TerrainPart::box);
    }
    for (const TerrainSlope& s : terrain.slopes) {
        auto top = [&](float x, float z) { return s.base + s.grade_x * (x - s.min_x) + s.grade_z * (z - s.min_z); };
        add_quad(mesh, vec3(s.min_x, top(s.min_x, s.min_z), s.min_z), vec3(s.min_x, top(s.min_x, s.max_z), s.max_z),
                 vec3(s.max_x, top(s.max_x, s.max_z), s.max_z), vec3(s.max_x, top(s.max_x, s.min_z), s.min_z),
                 TerrainPart::slope);
        add_walls(mesh, s.min_x, s.min_z, s.max_x, s.max_z, bottom, top, TerrainPart::slope);
    }
    return mesh;
}

}  // namespace marionette::render
