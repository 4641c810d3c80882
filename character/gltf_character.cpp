#include "character/gltf_character.hpp"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "character/gltf_detail.hpp"
#include "runtime/anim/clip.hpp"
#include "runtime/errors/import_error.hpp"

namespace marionette::character {

namespace {
using detail::read_indices;
using detail::read_joints;
using detail::read_mat4;
using detail::read_vec3;
using detail::read_weights;

// Images are never decoded: a character's textures are not drawn.
bool skip_image(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) {
    return true;
}

tinygltf::Model parse_model(const std::string& bytes, const std::string& file, const std::string& base_dir) {
    if (bytes.size() > gltf_limits::kMaxFileBytes)
        throw ImportError(file, 0, "the file is " + std::to_string(bytes.size()) + " bytes, over the limit of " +
                                       std::to_string(gltf_limits::kMaxFileBytes));
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(skip_image, nullptr);
    tinygltf::Model model;
    std::string err, warn;
    bool ok = false;
    const bool binary = bytes.size() >= 4 && bytes.compare(0, 4, "glTF") == 0;
    try {
        if (binary)
            ok = loader.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                             static_cast<unsigned int>(bytes.size()), base_dir);
        else
            ok = loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(), static_cast<unsigned int>(bytes.size()),
                                            base_dir);
    } catch (const std::exception& e) {
        throw ImportError(file, 0, std::string("not a readable glTF file: ") + e.what());
    }
    if (!ok) {
        while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
        std::replace(err.begin(), err.end(), '\n', ';');
        throw ImportError(file, 0, std::string(binary ? "not a readable .glb file: " : "not a readable glTF file: ") +
                                       (err.empty() ? "tinygltf gave no reason" : err));
    }
    return model;
}

// The first node with both a mesh and a skin.
const tinygltf::Node& skinned_node(const tinygltf::Model& m, const std::string& file) {
    if (m.meshes.empty()) throw ImportError(file, 0, "no mesh: the file holds no meshes");
    for (const tinygltf::Node& n : m.nodes) {
        if (n.mesh < 0 || n.skin < 0) continue;
        if (static_cast<std::size_t>(n.mesh) >= m.meshes.size())
            throw ImportError(file, 0, "node '" + n.name + "': mesh index " + std::to_string(n.mesh) + " is out of range");
        if (static_cast<std::size_t>(n.skin) >= m.skins.size())
            throw ImportError(file, 0, "node '" + n.name + "': skin index " + std::to_string(n.skin) + " is out of range");
        return n;
    }
    throw ImportError(file, 0, "no skin: no node has both a mesh and a skin (the character must be a skinned mesh)");
}

// Parent node of each node (−1 for roots); rejects a node with two parents,
// a child index out of range and cycles.
std::vector<int> node_parents(const tinygltf::Model& m, const std::string& file) {
    std::vector<int> parent(m.nodes.size(), -1);
    for (std::size_t i = 0; i < m.nodes.size(); ++i)
        for (int c : m.nodes[i].children) {
            if (c < 0 || static_cast<std::size_t>(c) >= m.nodes.size())
                throw ImportError(file, 0, "node " + std::to_string(i) + ": child index " + std::to_string(c) + " is out of range");
            if (parent[static_cast<std::size_t>(c)] != -1 || static_cast<std::size_t>(c) == i)
                throw ImportError(file, 0, "node " + std::to_string(c) + " has two parents (the nodes must form trees)");
            parent[static_cast<std::size_t>(c)] = static_cast<int>(i);
        }
    for (std::size_t i = 0; i < m.nodes.size(); ++i) {
        int depth = 0;
        for (int p = parent[i]; p >= 0; p = parent[static_cast<std::size_t>(p)])
            if (++depth > gltf_limits::kMaxNodeDepth)
                throw ImportError(file, 0, "node " + std::to_string(i) + ": the node hierarchy has a cycle or is deeper than " +
                                               std::to_string(gltf_limits::kMaxNodeDepth));
    }
    return parent;
}

glm::mat4 local_matrix(const tinygltf::Node& n, int index, const std::string& file) {
    const auto bad = [&](const char* what) {
        return ImportError(file, 0, "node " + std::to_string(index) + ": " + what);
    };
    glm::mat4 m(1.0f);
    if (!n.matrix.empty()) {
        if (n.matrix.size() != 16) throw bad("matrix must have 16 numbers");
        for (int i = 0; i < 16; ++i) glm::value_ptr(m)[i] = static_cast<float>(n.matrix[static_cast<std::size_t>(i)]);
    } else {
        if ((!n.translation.empty() && n.translation.size() != 3) || (!n.rotation.empty() && n.rotation.size() != 4) ||
            (!n.scale.empty() && n.scale.size() != 3))
            throw bad("translation, rotation or scale has the wrong number of components");
        glm::vec3 t(0.0f), s(1.0f);
        glm::quat r(1.0f, 0.0f, 0.0f, 0.0f);
        for (std::size_t i = 0; i < n.translation.size(); ++i) t[static_cast<int>(i)] = static_cast<float>(n.translation[i]);
        for (std::size_t i = 0; i < n.scale.size(); ++i) s[static_cast<int>(i)] = static_cast<float>(n.scale[i]);
        if (n.rotation.size() == 4)
            r = glm::quat(static_cast<float>(n.rotation[3]), static_cast<float>(n.rotation[0]),
                          static_cast<float>(n.rotation[1]), static_cast<float>(n.rotation[2]));
        m = glm::translate(glm::mat4(1.0f), t) * glm::mat4_cast(r) * glm::scale(glm::mat4(1.0f), s);
    }
    for (int i = 0; i < 16; ++i)
        if (!std::isfinite(glm::value_ptr(m)[i])) throw bad("its transform is not finite");
    return m;
}

struct SkinSkeleton {
    Clip clip;                      // joints in parent-first order, one rest frame
    std::vector<int> clip_of_skin;  // skin joint → clip joint, −1 for an end site
    std::vector<int> skin_parent;   // skin joint → skin parent, −1 for a root
    std::vector<std::string> names; // skin order
};

// Bind-pose positions of the skin's joints: from the inverse bind matrices when
// given, else from the node hierarchy.
std::vector<vec3> bind_positions(const tinygltf::Model& m, const tinygltf::Skin& skin, const std::vector<int>& parent,
                                 const std::string& file) {
    const std::size_t n = skin.joints.size();
    std::vector<vec3> out(n);
    if (skin.inverseBindMatrices >= 0) {
        const auto ibm = read_mat4(m, skin.inverseBindMatrices, "inverseBindMatrices", file);
        if (ibm.size() != n)
            throw ImportError(file, 0, "skin: " + std::to_string(ibm.size()) + " inverse bind matrices for " +
                                           std::to_string(n) + " joints");
        for (std::size_t j = 0; j < n; ++j) {
            const glm::mat4 inv = glm::make_mat4(ibm[j].data());
            const float det = glm::determinant(inv);
            if (!std::isfinite(det) || std::abs(det) < 1e-12f)
                throw ImportError(file, 0, "skin: inverse bind matrix " + std::to_string(j) + " is not invertible");
            const glm::vec4 p = glm::inverse(inv)[3];
            out[j] = vec3(p) / p.w;
            if (!std::isfinite(out[j].x) || !std::isfinite(out[j].y) || !std::isfinite(out[j].z))
                throw ImportError(file, 0, "skin: inverse bind matrix " + std::to_string(j) + " is not finite");
        }
        return out;
    }
    for (std::size_t j = 0; j < n; ++j) {
        glm::mat4 world(1.0f);
        for (int node = skin.joints[j]; node >= 0; node = parent[static_cast<std::size_t>(node)])
            world = local_matrix(m.nodes[static_cast<std::size_t>(node)], node, file) * world;
        out[j] = vec3(world[3]);
    }
    return out;
}

// The skin as a clip skeleton. With `leaves_as_end_sites`, leaf joints (the
// *_End joints exporters add) become end sites of their parents, as in BVH.
SkinSkeleton skin_skeleton(const tinygltf::Model& m, const tinygltf::Skin& skin, const std::string& file,
                           bool leaves_as_end_sites) {
    const std::size_t n = skin.joints.size();
    if (n == 0) throw ImportError(file, 0, "skin: it has no joints");
    if (n > gltf_limits::kMaxSkinJoints)
        throw ImportError(file, 0, "skin: " + std::to_string(n) + " joints, over the limit of " +
                                       std::to_string(gltf_limits::kMaxSkinJoints));
    std::vector<int> skin_of_node(m.nodes.size(), -1);
    for (std::size_t j = 0; j < n; ++j) {
        const int node = skin.joints[j];
        if (node < 0 || static_cast<std::size_t>(node) >= m.nodes.size())
            throw ImportError(file, 0, "skin: joint " + std::to_string(j) + " names node " + std::to_string(node) + ", out of range");
        if (skin_of_node[static_cast<std::size_t>(node)] >= 0)
            throw ImportError(file, 0, "skin: node " + std::to_string(node) + " is listed twice among the joints");
        skin_of_node[static_cast<std::size_t>(node)] = static_cast<int>(j);
    }
    const std::vector<int> parent = node_parents(m, file);
    const std::vector<vec3> pos = bind_positions(m, skin, parent, file);
    // Skin parent: nearest ancestor node that is a joint.
    std::vector<int> skin_parent(n, -1);
    for (std::size_t j = 0; j < n; ++j)
        for (int p = parent[static_cast<std::size_t>(skin.joints[j])]; p >= 0; p = parent[static_cast<std::size_t>(p)])
            if (skin_of_node[static_cast<std::size_t>(p)] >= 0) {
                skin_parent[j] = skin_of_node[static_cast<std::size_t>(p)];
                break;
            }
    SkinSkeleton out;
    out.skin_parent = skin_parent;
    out.clip_of_skin.assign(n, -1);
    std::vector<bool> end(n, false);
    if (leaves_as_end_sites) {
        std::vector<bool> has_kids(n, false);
        for (std::size_t j = 0; j < n; ++j)
            if (skin_parent[j] >= 0) has_kids[static_cast<std::size_t>(skin_parent[j])] = true;
        for (std::size_t j = 0; j < n; ++j) end[j] = !has_kids[j] && skin_parent[j] >= 0;
    }
    std::vector<int> order;  // parents first; node_parents ruled out cycles
    for (std::size_t placed = n + 1; placed != order.size();) {
        placed = order.size();
        for (std::size_t j = 0; j < n; ++j)
            if (!end[j] && out.clip_of_skin[j] < 0 &&
                (skin_parent[j] < 0 || out.clip_of_skin[static_cast<std::size_t>(skin_parent[j])] >= 0)) {
                out.clip_of_skin[j] = static_cast<int>(order.size());
                order.push_back(static_cast<int>(j));
            }
    }
    Skeleton& s = out.clip.skeleton;
    for (std::size_t j = 0; j < n; ++j) {
        std::string name = m.nodes[static_cast<std::size_t>(skin.joints[j])].name;
        if (name.empty()) name = "joint_" + std::to_string(j);
        for (const std::string& other : out.names)
            if (other == name) name += "_" + std::to_string(j);
        out.names.push_back(name);
    }
    for (int j : order) {
        const int p = skin_parent[static_cast<std::size_t>(j)];
        s.joint_names.push_back(out.names[static_cast<std::size_t>(j)]);
        s.parents.push_back(p < 0 ? kNoParent : out.clip_of_skin[static_cast<std::size_t>(p)]);
        s.rest_offsets.push_back(pos[static_cast<std::size_t>(j)] - (p < 0 ? vec3(0.0f) : pos[static_cast<std::size_t>(p)]));
    }
    for (std::size_t j = 0; j < n; ++j)
        if (end[j]) {
            const auto p = static_cast<std::size_t>(skin_parent[j]);
            s.end_site_parents.push_back(out.clip_of_skin[p]);
            s.end_site_offsets.push_back(pos[j] - pos[p]);
        }
    const std::size_t joints = order.size();
    out.clip.name = file;
    out.clip.frame_count = 1;
    out.clip.rotations.assign(joints, quat(1.0f, 0.0f, 0.0f, 0.0f));
    out.clip.translations = s.rest_offsets;
    out.clip.animated_translation.assign(joints, false);
    out.clip.animated_translation[0] = true;
    return out;
}

struct RawMesh {
    std::vector<std::array<float, 3>> positions, normals;
    std::vector<std::array<std::uint16_t, 4>> joints;
    std::vector<std::array<float, 4>> weights;
    std::vector<std::uint32_t> indices;
    bool has_normals = true;
};

void append_primitive(const tinygltf::Model& m, const tinygltf::Primitive& p, std::size_t index, std::size_t skin_joints,
                      const std::string& file, RawMesh& raw) {
    const std::string where = "primitive " + std::to_string(index);
    if (p.mode != TINYGLTF_MODE_TRIANGLES)
        throw ImportError(file, 0, where + ": mode " + std::to_string(p.mode) + " is not supported (only triangles, mode 4)");
    const auto attribute = [&](const char* name) {
        const auto it = p.attributes.find(name);
        return it == p.attributes.end() ? -1 : it->second;
    };
    if (attribute("JOINTS_1") >= 0 || attribute("WEIGHTS_1") >= 0)
        throw ImportError(file, 0, where + ": more than 4 joints per vertex (JOINTS_1/WEIGHTS_1) is not supported");
    if (attribute("POSITION") < 0) throw ImportError(file, 0, where + ": no POSITION attribute");
    if (attribute("JOINTS_0") < 0 || attribute("WEIGHTS_0") < 0)
        throw ImportError(file, 0, where + ": not skinned (no JOINTS_0 and WEIGHTS_0 attributes)");
    const auto positions = read_vec3(m, attribute("POSITION"), "POSITION", file);
    const std::size_t count = positions.size();
    const std::size_t base = raw.positions.size();
    if (base + count > gltf_limits::kMaxVertices)
        throw ImportError(file, 0, where + ": " + std::to_string(base + count) + " vertices, over the limit of " +
                                       std::to_string(gltf_limits::kMaxVertices));
    const auto joints = read_joints(m, attribute("JOINTS_0"), "JOINTS_0", file);
    const auto weights = read_weights(m, attribute("WEIGHTS_0"), "WEIGHTS_0", file);
    std::vector<std::array<float, 3>> normals;
    if (attribute("NORMAL") >= 0) normals = read_vec3(m, attribute("NORMAL"), "NORMAL", file);
    if (joints.size() != count || weights.size() != count || (!normals.empty() && normals.size() != count))
        throw ImportError(file, 0, where + ": its attributes have different counts (POSITION has " + std::to_string(count) + ")");
    for (std::size_t v = 0; v < count; ++v) {
        for (std::uint16_t j : joints[v])
            if (j >= skin_joints)
                throw ImportError(file, 0, where + ": vertex " + std::to_string(v) + " names joint " + std::to_string(j) +
                                               " of a skin with " + std::to_string(skin_joints));
        if (!(weights[v][0] + weights[v][1] + weights[v][2] + weights[v][3] > 1e-6f))
            throw ImportError(file, 0, where + ": vertex " + std::to_string(v) + " has no weight");
    }
    std::vector<std::uint32_t> indices;
    if (p.indices >= 0) indices = read_indices(m, p.indices, "indices", file);
    else for (std::uint32_t i = 0; i < count; ++i) indices.push_back(i);
    if (indices.size() % 3 != 0)
        throw ImportError(file, 0, where + ": " + std::to_string(indices.size()) + " indices is not a whole number of triangles");
    if (raw.indices.size() + indices.size() > gltf_limits::kMaxIndices)
        throw ImportError(file, 0, where + ": over the limit of " + std::to_string(gltf_limits::kMaxIndices) + " indices");
    for (std::size_t i = 0; i < indices.size(); ++i) {
        if (indices[i] >= count)
            throw ImportError(file, 0, where + ": index " + std::to_string(i) + " is " + std::to_string(indices[i]) +
                                           ", out of range for " + std::to_string(count) + " vertices");
        raw.indices.push_back(static_cast<std::uint32_t>(base) + indices[i]);
    }
    raw.positions.insert(raw.positions.end(), positions.begin(), positions.end());
    raw.joints.insert(raw.joints.end(), joints.begin(), joints.end());
    raw.weights.insert(raw.weights.end(), weights.begin(), weights.end());
    raw.has_normals = raw.has_normals && !normals.empty();
    normals.resize(count);
    raw.normals.insert(raw.normals.end(), normals.begin(), normals.end());
}

// Area-weighted vertex normals, for meshes without NORMAL.
void compute_normals(RawMesh& raw) {
    std::vector<vec3> n(raw.positions.size(), vec3(0.0f));
    const auto at = [&](std::uint32_t i) { return glm::make_vec3(raw.positions[i].data()); };
    for (std::size_t t = 0; t + 2 < raw.indices.size(); t += 3) {
        const std::uint32_t a = raw.indices[t], b = raw.indices[t + 1], c = raw.indices[t + 2];
        const vec3 face = glm::cross(at(b) - at(a), at(c) - at(a));
        n[a] += face;
        n[b] += face;
        n[c] += face;
    }
    for (std::size_t v = 0; v < n.size(); ++v) {
        const float l = glm::length(n[v]);
        const vec3 u = l > 1e-12f ? n[v] / l : vec3(0, 1, 0);
        raw.normals[v] = {u.x, u.y, u.z};
    }
}

// Shortest rotation turning unit vector a onto unit vector b.
quat rotation_between(vec3 a, vec3 b) {
    const float d = glm::dot(a, b);
    if (d < -0.9999f) {
        vec3 axis = glm::cross(vec3(1, 0, 0), a);
        if (glm::length(axis) < 1e-3f) axis = glm::cross(vec3(0, 0, 1), a);
        return glm::angleAxis(3.14159265f, glm::normalize(axis));
    }
    const vec3 c = glm::cross(a, b);
    return glm::normalize(quat(1.0f + d, c.x, c.y, c.z));
}

render::BodyPart part_of_role(int role) {
    if (role >= retarget::role::clavicle_l && role <= retarget::role::hand_l) return render::BodyPart::left;
    if (role >= retarget::role::thigh_l && role <= retarget::role::toe_l) return render::BodyPart::left;
    if (role >= retarget::role::clavicle_r && role <= retarget::role::hand_r) return render::BodyPart::right;
    if (role >= retarget::role::thigh_r && role <= retarget::role::toe_r) return render::BodyPart::right;
    return render::BodyPart::body;
}

struct PuppetRest {
    std::vector<quat> rotations;
    std::vector<vec3> positions;
};

PuppetRest puppet_rest(const Skeleton& puppet) {
    const auto n = static_cast<std::size_t>(puppet.joint_count());
    if (n != static_cast<std::size_t>(retarget::kRoleCount))
        throw std::invalid_argument("a glTF character maps onto the puppet's 22 joints; this skeleton has " + std::to_string(n));
    const Pose rest = rest_pose(puppet);
    PuppetRest out{std::vector<quat>(n), std::vector<vec3>(n)};
    const LocalToModelJob fk{puppet.parents, {rest.local_rotations, rest.local_translations}, {out.rotations, out.positions}};
    if (!fk.run()) throw std::invalid_argument("the puppet skeleton is not in topological order");
    return out;
}

// Direction of the puppet's bone for `role` at rest (to its child role, or to its end site).
vec3 puppet_bone(const Skeleton& puppet, const PuppetRest& rest, int role) {
    const int child = retarget::child_role(role);
    if (child >= 0) return rest.positions[static_cast<std::size_t>(child)] - rest.positions[static_cast<std::size_t>(role)];
    for (std::size_t e = 0; e < puppet.end_site_parents.size(); ++e)
        if (puppet.end_site_parents[e] == role) return rest.rotations[static_cast<std::size_t>(role)] * puppet.end_site_offsets[e];
    return vec3(0, 1, 0);
}

// The mapping: per role, the inverse bind that carries the character's vertices
// (already placed: scaled and stood under the puppet) onto the puppet's bone.
void bind_roles(const Skeleton& puppet, const retarget::HumanoidChains& h, const std::vector<vec3>& clip_pos,
                float scale, vec3 char_origin, CharacterMesh& out) {
    const PuppetRest rest = puppet_rest(puppet);
    const vec3 puppet_origin(rest.positions[0].x, 0.0f, rest.positions[0].z);
    const auto place = [&](vec3 p) { return (p - char_origin) * scale + puppet_origin; };
    const auto point = [&](const retarget::SourcePoint& s) {
        const vec3 a = clip_pos.at(static_cast<std::size_t>(s.a));
        return s.b < 0 ? a : a + s.t * (clip_pos.at(static_cast<std::size_t>(s.b)) - a);
    };
    out.mesh.inverse_bind.clear();
    for (int r = 0; r < retarget::kRoleCount; ++r) {
        const auto i = static_cast<std::size_t>(r);
        const vec3 from = place(point(h.from[i])), to = place(point(h.to[i]));
        const vec3 source_dir = to - from;
        const vec3 target_dir = puppet_bone(puppet, rest, r);
        quat align(1.0f, 0.0f, 0.0f, 0.0f);
        if (glm::length(source_dir) > 1e-6f && glm::length(target_dir) > 1e-6f)
            align = rotation_between(glm::normalize(source_dir), glm::normalize(target_dir));
        const vec3 joint = place(clip_pos.at(static_cast<std::size_t>(h.joint[i])));
        const glm::mat4 m = glm::mat4_cast(glm::inverse(rest.rotations[i]) * align) * glm::translate(glm::mat4(1.0f), -joint);
        std::array<float, 16> column_major{};
        std::copy(glm::value_ptr(m), glm::value_ptr(m) + 16, column_major.begin());
        out.mesh.inverse_bind.push_back(column_major);
    }
    out.scale = scale;
}

// Per skin joint, the role of its nearest mapped ancestor (itself included).
std::vector<int> roles_of_skin(const SkinSkeleton& sk, const retarget::HumanoidChains& h) {
    const std::size_t n = sk.clip_of_skin.size();
    const auto joints = static_cast<std::size_t>(sk.clip.joint_count());
    std::vector<int> role_of_clip(joints, -1);
    for (int r = 0; r < retarget::kRoleCount; ++r) {
        const int j = h.joint[static_cast<std::size_t>(r)];
        if (j >= 0 && static_cast<std::size_t>(j) < joints && role_of_clip[static_cast<std::size_t>(j)] < 0)
            role_of_clip[static_cast<std::size_t>(j)] = r;
    }
    // Clip order is parents first, so one pass inherits.
    const Skeleton& s = sk.clip.skeleton;
    for (std::size_t j = 0; j < joints; ++j)
        if (role_of_clip[j] < 0) {
            const int p = s.parents[j];
            role_of_clip[j] = p == kNoParent ? retarget::role::pelvis : role_of_clip[static_cast<std::size_t>(p)];
        }
    std::vector<int> out(n);
    for (std::size_t j = 0; j < n; ++j) {
        const int c = sk.clip_of_skin[j] >= 0 ? sk.clip_of_skin[j] : sk.clip_of_skin[static_cast<std::size_t>(sk.skin_parent[j])];
        out[j] = role_of_clip[static_cast<std::size_t>(c)];
    }
    return out;
}

void build_vertices(const RawMesh& raw, const std::vector<int>& role_of_skin, float scale, vec3 char_origin,
                    vec3 puppet_origin, CharacterMesh& out) {
    out.mesh.vertices.resize(raw.positions.size());
    for (std::size_t v = 0; v < raw.positions.size(); ++v) {
        render::SkinnedVertex& o = out.mesh.vertices[v];
        const vec3 p = (glm::make_vec3(raw.positions[v].data()) - char_origin) * scale + puppet_origin;
        o.position = {p.x, p.y, p.z};
        o.normal = raw.normals[v];
        // Merge the four influences by puppet joint, then renormalise.
        std::array<int, 4> role{};
        std::array<float, 4> weight{};
        int used = 0;
        float total = 0.0f;
        for (std::size_t k = 0; k < 4; ++k) {
            const int r = role_of_skin[raw.joints[v][k]];
            const float w = raw.weights[v][k];
            if (w <= 0.0f) continue;
            total += w;
            int slot = 0;
            while (slot < used && role[static_cast<std::size_t>(slot)] != r) ++slot;
            if (slot == used) role[static_cast<std::size_t>(used++)] = r;
            weight[static_cast<std::size_t>(slot)] += w;
        }
        int heaviest = 0;
        for (int k = 0; k < used; ++k) {
            const auto i = static_cast<std::size_t>(k);
            o.joints[i] = static_cast<std::uint8_t>(role[i]);
            o.weights[i] = weight[i] / total;
            if (weight[i] > weight[static_cast<std::size_t>(heaviest)]) heaviest = k;
        }
        o.part = static_cast<std::uint8_t>(part_of_role(role[static_cast<std::size_t>(heaviest)]));
    }
    out.mesh.indices.assign(raw.indices.begin(), raw.indices.end());  // < kMaxVertices: fits 16 bits
}
}  // namespace

CharacterMesh load_gltf_character_bytes(const std::string& bytes, const std::string& file, const std::string& base_dir,
                                        const Skeleton& puppet, const retarget::RetargetMap* map) {
    const tinygltf::Model model = parse_model(bytes, file, base_dir);
    const tinygltf::Node& node = skinned_node(model, file);
    const tinygltf::Skin& skin = model.skins[static_cast<std::size_t>(node.skin)];
    const tinygltf::Mesh& mesh = model.meshes[static_cast<std::size_t>(node.mesh)];

    RawMesh raw;
    if (mesh.primitives.empty()) throw ImportError(file, 0, "mesh '" + mesh.name + "' has no primitives");
    for (std::size_t p = 0; p < mesh.primitives.size(); ++p)
        append_primitive(model, mesh.primitives[p], p, skin.joints.size(), file, raw);
    if (raw.indices.empty()) throw ImportError(file, 0, "mesh '" + mesh.name + "' has no triangles");
    if (!raw.has_normals) compute_normals(raw);

    // Leaf joints as end sites first (what exporters' *_End joints are), then as joints.
    SkinSkeleton sk;
    retarget::HumanoidChains h;
    std::string first_problem;
    for (bool leaves_as_end_sites : {true, false}) {
        sk = skin_skeleton(model, skin, file, leaves_as_end_sites);
        try {
            h = retarget::detect_humanoid(sk.clip, file, map);
            first_problem.clear();
            break;
        } catch (const ParseError& e) {
            if (first_problem.empty())
                first_problem = e.file().empty() || e.file() == file ? e.message() : std::string(e.what());
        }
    }
    if (!first_problem.empty()) throw ImportError(file, 0, "cannot map the skeleton onto the puppet's: " + first_problem);
    if (!(h.source_leg_length > 1e-6f) || !std::isfinite(h.source_leg_length))
        throw ImportError(file, 0, "cannot map the skeleton onto the puppet's: the legs have no length");

    // Rest positions of the clip's joints, then of its end sites (index J + e).
    const Skeleton& cs = sk.clip.skeleton;
    std::vector<vec3> clip_pos(cs.rest_offsets);
    for (std::size_t j = 0; j < clip_pos.size(); ++j)
        if (cs.parents[j] != kNoParent) clip_pos[j] += clip_pos[static_cast<std::size_t>(cs.parents[j])];
    for (std::size_t e = 0; e < cs.end_site_parents.size(); ++e)
        clip_pos.push_back(clip_pos[static_cast<std::size_t>(cs.end_site_parents[e])] + cs.end_site_offsets[e]);

    CharacterMesh out;
    out.skin_joints = sk.names;
    out.role_of_skin_joint = roles_of_skin(sk, h);
    out.side_from = h.side_from;
    for (int r = 0; r < retarget::kRoleCount; ++r)
        out.role_joint[static_cast<std::size_t>(r)] = sk.clip.skeleton.joint_names[static_cast<std::size_t>(h.joint[static_cast<std::size_t>(r)])];
    const PuppetRest rest = puppet_rest(puppet);
    const float hip_height = rest.positions[static_cast<std::size_t>(retarget::role::thigh_l)].y;
    const float scale = hip_height / h.source_leg_length;
    const vec3 pelvis = clip_pos[static_cast<std::size_t>(h.joint[retarget::role::pelvis])];
    const vec3 char_origin(pelvis.x, h.source_floor, pelvis.z);
    bind_roles(puppet, h, clip_pos, scale, char_origin, out);
    build_vertices(raw, out.role_of_skin_joint, scale, char_origin, vec3(rest.positions[0].x, 0.0f, rest.positions[0].z), out);
    return out;
}

CharacterMesh load_gltf_character(const std::string& path, const Skeleton& puppet, const retarget::RetargetMap* map) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw ImportError(path, 0, "cannot open the file");
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (size < 0) throw ImportError(path, 0, "cannot read the file");
    if (static_cast<std::uint64_t>(size) > gltf_limits::kMaxFileBytes)
        throw ImportError(path, 0, "the file is " + std::to_string(size) + " bytes, over the limit of " +
                                       std::to_string(gltf_limits::kMaxFileBytes));
    in.seekg(0);
    std::string bytes(static_cast<std::size_t>(size), '\0');
    in.read(bytes.data(), size);
    if (!in) throw ImportError(path, 0, "cannot read the file");
    const std::size_t slash = path.find_last_of('/');
    const std::string base_dir = slash == std::string::npos ? "." : path.substr(0, slash);
    return load_gltf_character_bytes(bytes, path, base_dir, puppet, map);
}

}  // namespace marionette::character
