#pragma once
// Your own character (docs/render.md): a skinned glTF 2.0 mesh (.gltf with
// embedded or side-by-side buffers, or .glb) turned into a mesh the renderer
// skins with the puppet's joints, so it walks exactly as the capsule puppet does.
//
// Mapping: the skin's joints become a skeleton (parent = nearest ancestor node
// that is a skin joint, positions from the inverse bind matrices), the humanoid
// chain detection of retarget/humanoid.hpp (or a `[retarget]` map naming the
// roles) finds the puppet's 22 roles in it, and every skin joint follows the
// role of its nearest mapped ancestor (itself included; unmapped roots follow
// the pelvis). The character is scaled so its hip height is the puppet's and
// stood on the ground under the puppet's pelvis, and each role's bone is turned
// from the character's rest direction onto the puppet's, so a T-pose character
// hangs its arms like the puppet.
//
// Load-time code: allocates, throws ImportError naming the file and what is
// wrong (never crashes on bad input). The envelope is in gltf_limits below.
#include <string>
#include <vector>

#include "render_es/mesh.hpp"
#include "retarget/humanoid.hpp"
#include "runtime/anim/skeleton.hpp"

namespace marionette::character {

namespace gltf_limits {
inline constexpr std::size_t kMaxFileBytes = 64u << 20;    // .gltf/.glb and each buffer
inline constexpr std::size_t kMaxVertices = 65535;          // the renderer's 16-bit indices
inline constexpr std::size_t kMaxIndices = 3u << 20;        // triangles × 3, all primitives
inline constexpr std::size_t kMaxSkinJoints = 256;
inline constexpr int kMaxNodeDepth = 256;
}  // namespace gltf_limits

struct CharacterMesh {
    render::SkinnedMesh mesh;               // joints are the puppet's
    std::vector<std::string> skin_joints;   // the glTF skin's joint names, skin order
    std::vector<int> role_of_skin_joint;    // puppet joint moving each skin joint
    std::array<std::string, retarget::kRoleCount> role_joint;  // skin joint name found per role
    float scale = 1.0f;                     // character units → metres on the puppet
    std::string side_from;                  // how left/right was decided
};

// Reads `path` (.glb when it starts with the binary magic, else glTF JSON).
// External buffer URIs are resolved next to the file. `map` (optional) names
// roles outright. Throws ImportError naming `path`.
CharacterMesh load_gltf_character(const std::string& path, const Skeleton& puppet,
                                  const retarget::RetargetMap* map = nullptr);

// The same from bytes already in memory; `file` names them in messages and
// `base_dir` resolves external buffers ("" allows none).
CharacterMesh load_gltf_character_bytes(const std::string& bytes, const std::string& file, const std::string& base_dir,
                                        const Skeleton& puppet, const retarget::RetargetMap* map = nullptr);

}  // namespace marionette::character
