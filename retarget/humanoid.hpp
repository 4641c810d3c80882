#pragma once
// Finding a humanoid in any skeleton (docs/retarget.md): the end effectors from
// the rest pose (head = the highest leaf, feet = the two lowest, hands = the two
// remaining limbs), the chains from each effector to the root, left and right
// from the facing direction (root travel against the hips; the toes when the
// root does not travel), names (CMU ASF, CMU BVH, Mixamo) confirming or
// overriding the side, and a `[retarget]` table that names any role outright.
// Offline code: allocates freely, throws ImportError naming the file.
#include <array>
#include <string>
#include <vector>

#include "runtime/anim/clip.hpp"

namespace marionette::retarget {

// A point of the source skeleton: joint `a` (or end site J + e, where J is the
// joint count) moved toward point `b` by `t` (t = 0: exactly `a`).
struct SourcePoint {
    int a = -1;
    int b = -1;
    float t = 0.0f;
};

// The roles of the puppet's bones, in the puppet's joint order
// (runtime/gait/puppet.hpp): role r is puppet joint r.
inline constexpr int kRoleCount = 22;
namespace role {
enum : int {
    pelvis, spine_01, spine_02, spine_03, neck, head,
    clavicle_l, upperarm_l, forearm_l, hand_l,
    clavicle_r, upperarm_r, forearm_r, hand_r,
    thigh_l, shin_l, foot_l, toe_l,
    thigh_r, shin_r, foot_r, toe_r,
};
}  // namespace role
// The role a role's bone points at (pelvis → spine_01, ..., thigh → shin), or
// −1 for the ends (head, hands, toes), whose bones end at an end site.
int child_role(int role);
// Map-file keys, one per role: "pelvis", "spine_01", ..., "toe_r" (the puppet's
// joint names).
const std::array<const char*, kRoleCount>& role_names();

struct HumanoidChains {
    // Per role: the source joint whose rotation drives the puppet bone, and the
    // two source points whose difference is the bone's direction.
    std::array<int, kRoleCount> joint{};
    std::array<SourcePoint, kRoleCount> from{};
    std::array<SourcePoint, kRoleCount> to{};
    // The leaves found: head, left foot, right foot, left hand, right hand.
    std::array<int, 5> effectors{};
    // How the sides were decided: "root travel", "toes", or "names" (names
    // overrode the geometry), and whether names agreed.
    std::string side_from;
    bool names_agree = true;
    std::vector<std::string> notes;  // map-file overrides, name corrections
    float source_leg_length = 0.0f;  // hip joint to the ground at rest, source units
    float source_floor = 0.0f;       // height of the ground under the rest pose
    // Where the puppet's spine_01 and spine_02 sit along the pelvis → chest
    // path (fractions of its length); the source's path is split the same way.
    std::array<float, 2> spine_fractions{0.231f, 0.615f};
};

// A `[retarget]` table: role name → source joint name, read from TOML.
struct RetargetMap {
    std::string origin;  // file name, for messages
    std::vector<std::pair<std::string, std::string>> roles;
    std::vector<int> lines;  // 1-based line of each role entry
    std::string up;          // "y" (default) or "z"
};

// Parses a map file: a `[retarget]` table whose keys are role names and whose
// values are joint names, plus an optional `up = "y" | "z"`. Other tables are
// allowed (a labels file may carry the table) when `allow_other_tables`. Throws
// ImportError naming the file, line and key.
RetargetMap parse_retarget_map(const std::string& toml_text, const std::string& origin, bool allow_other_tables = false);

// Finds the humanoid in `clip` (its rest pose and, for the sides, its motion).
// `map` may be null. Throws ImportError naming `file` when no humanoid is
// found or the map names a joint the skeleton lacks.
HumanoidChains detect_humanoid(const Clip& clip, const std::string& file, const RetargetMap* map,
                               std::array<float, 2> spine_fractions = {0.231f, 0.615f});

// +1 when a joint name says left, −1 right, 0 when it does not say (exposed for tests).
int side_of_name(const std::string& name);

}  // namespace marionette::retarget
