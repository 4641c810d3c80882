#pragma once
// Meshes the renderer uploads, generated on the CPU as plain arrays (no GL here,
// so they are tested without a context): capsules around the skeleton's bones,
// skinned with up to 4 weights, and the terrain's heightfield, boxes and slopes.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "runtime/anim/skeleton.hpp"
#include "runtime/ground/terrain.hpp"

namespace marionette::render {

inline constexpr int kMaxBones = 64;

enum class BodyPart : std::uint8_t { body = 0, left = 1, right = 2 };

struct SkinnedVertex {
    std::array<float, 3> position{};  // rest pose, model space
    std::array<float, 3> normal{};
    std::array<std::uint8_t, 4> joints{};
    std::array<float, 4> weights{};   // sum to 1
    std::uint8_t part = 0;            // BodyPart: picks the colour
    std::array<std::uint8_t, 3> padding{};
};

struct SkinnedMesh {
    std::vector<SkinnedVertex> vertices;
    std::vector<std::uint16_t> indices;  // triangles
    // Rest-pose model transform of each joint, inverted: bone matrix = current model
    // transform × inverse_bind.
    std::vector<std::array<float, 16>> inverse_bind;  // column-major
};

struct CapsuleMeshSettings {
    int sides = 12;          // around each capsule
    int cap_rings = 3;       // per hemisphere
    int body_rings = 4;      // along the cylinder
};

// Capsule radius for a bone driven by the named joint: a table for the default
// puppet's names (pelvis, spine_*, thigh_*, ...), else a fraction of its length.
float capsule_radius(const std::string& joint_name, float bone_length);

// One capsule per bone (parent joint → child joint or end site), driven by the
// parent joint and blended with its neighbour near each end so joints bend
// smoothly. Rest model transforms come from FK of the skeleton's rest pose.
// Throws std::invalid_argument for a skeleton over kMaxBones joints or a mesh
// over 65535 vertices.
SkinnedMesh make_capsule_mesh(const Skeleton& skeleton, const CapsuleMeshSettings& settings = {});

enum class TerrainPart : std::uint8_t { ground = 0, box = 1, slope = 2 };

struct TerrainVertex {
    std::array<float, 3> position{};
    std::array<float, 3> normal{};
    float part = 0.0f;                // TerrainPart, as a float attribute
};

struct TerrainMesh {
    std::vector<TerrainVertex> vertices;
    std::vector<std::uint32_t> indices;
};

// Flat ground of ±ground_extent_m around the origin when the terrain has no
// heightfield (else the heightfield grid), plus every box (top and four sides)
// and slope (top and sides) standing on the ground below them.
TerrainMesh make_terrain_mesh(const Terrain& terrain, float ground_extent_m = 60.0f);

}  // namespace marionette::render
