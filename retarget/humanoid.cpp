#include "retarget/humanoid.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>

#include "retarget/pose_space.hpp"
#include "runtime/errors/import_error.hpp"

namespace marionette::retarget {

namespace {

// Puppet joint indices (runtime/gait/puppet.hpp), repeated here as roles so the
// detector does not depend on the gait.
enum Role : int {
    kPelvis, kSpine1, kSpine2, kSpine3, kNeck, kHead,
    kClavicleL, kUpperArmL, kForearmL, kHandL,
    kClavicleR, kUpperArmR, kForearmR, kHandR,
    kThighL, kShinL, kFootL, kToeL,
    kThighR, kShinR, kFootR, kToeR,
};

std::string lower(std::string s) {
    for (char& c : s) c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
    return s;
}

struct Limb {
    int start = -1;          // the limb's first joint (child of its attachment)
    int attachment = -1;     // the spine joint it hangs from
    std::vector<int> leaves;
    float lowest = 0.0f;     // lowest height of its leaves' points
    float reach = 0.0f;      // farthest leaf point from the attachment
};

struct Rest {
    const Skeleton* s = nullptr;
    std::vector<vec3> p;                 // joints then end sites, world, rest pose
    std::vector<std::vector<int>> kids;  // joint children
    int joints = 0;
    float height(int point) const { return p[static_cast<size_t>(point)].y; }
    // The highest / lowest of a joint and its end sites.
    float extreme(int j, bool highest) const {
        float h = height(j);
        for (size_t e = 0; e < s->end_site_parents.size(); ++e)
            if (s->end_site_parents[e] == j) {
                const float he = height(joints + static_cast<int>(e));
                h = highest ? std::max(h, he) : std::min(h, he);
            }
        return h;
    }
    int end_site_of(int j) const {
        for (size_t e = 0; e < s->end_site_parents.size(); ++e)
            if (s->end_site_parents[e] == j) return joints + static_cast<int>(e);
        return -1;
    }
    float dist(int a, int b) const { return glm::length(p[static_cast<size_t>(a)] - p[static_cast<size_t>(b)]); }
};

Rest make_rest(const Skeleton& s) {
    Rest r;
    r.s = &s;
    r.joints = s.joint_count();
    std::vector<quat> rot;
    rest_model_pose(s, rot, r.p);
    r.kids.resize(static_cast<size_t>(r.joints));
    for (int j = 0; j < r.joints; ++j)
        if (s.parents[static_cast<size_t>(j)] != kNoParent) r.kids[static_cast<size_t>(s.parents[static_cast<size_t>(j)])].push_back(j);
    return r;
}

// Joints from `top` (exclusive) down to `bottom` (inclusive), top first.
std::vector<int> path_down(const Skeleton& s, int top, int bottom) {
    std::vector<int> path;
    for (int j = bottom; j != top && j != kNoParent; j = s.parents[static_cast<size_t>(j)]) path.push_back(j);
    std::reverse(path.begin(), path.end());
    return path;
}

[[noreturn]] void not_humanoid(const std::string& file, const std::string& why) {
    throw ImportError(file, 0, "no humanoid found: " + why +
                                   " (add a [retarget] table naming the joints: --map FILE, docs/retarget.md)");
}

struct Found {
    std::vector<int> spine;  // root .. head leaf
    std::array<Limb, 4> limbs;  // leg A, leg B, arm A, arm B
    int head_leaf = -1;
};

Found find_limbs(const Rest& r, const std::string& file) {
    Found f;
    std::vector<int> leaves;
    for (int j = 0; j < r.joints; ++j)
        if (r.kids[static_cast<size_t>(j)].empty()) leaves.push_back(j);
    if (leaves.size() < 5)
        not_humanoid(file, std::to_string(leaves.size()) + " leaf joints (a humanoid has at least 5: head, hands, feet)");
    for (int l : leaves)
        if (f.head_leaf < 0 || r.extreme(l, true) > r.extreme(f.head_leaf, true)) f.head_leaf = l;
    f.spine = path_down(*r.s, kNoParent, f.head_leaf);
    std::vector<bool> on_spine(static_cast<size_t>(r.joints), false);
    for (int j : f.spine) on_spine[static_cast<size_t>(j)] = true;
    std::vector<Limb> limbs;
    for (int l : leaves) {
        if (l == f.head_leaf) continue;
        int start = l;
        // A leaf of another tree (a skeleton with two roots) never meets the spine.
        for (;;) {
            const int p = r.s->parents[static_cast<size_t>(start)];
            if (p == kNoParent)
                not_humanoid(file, "leaf '" + r.s->joint_names[static_cast<size_t>(l)] +
                                       "' is not in the head's tree (the skeleton has more than one root)");
            if (on_spine[static_cast<size_t>(p)]) break;
            start = p;
        }
        auto it = std::find_if(limbs.begin(), limbs.end(), [&](const Limb& m) { return m.start == start; });
        if (it == limbs.end()) {
            Limb m;
            m.start = start;
            m.attachment = r.s->parents[static_cast<size_t>(start)];
            m.lowest = r.extreme(l, false);
            limbs.push_back(m);
            it = limbs.end() - 1;
        }
        it->leaves.push_back(l);
        it->lowest = std::min(it->lowest, r.extreme(l, false));
        const int end = r.end_site_of(l);
        it->reach = std::max({it->reach, r.dist(l, it->attachment), end >= 0 ? r.dist(end, it->attachment) : 0.0f});
    }
    if (limbs.size() < 4)
        not_humanoid(file, std::to_string(limbs.size()) + " limbs branch off the path from the root to the head '" +
                               r.s->joint_names[static_cast<size_t>(f.head_leaf)] + "' (a humanoid has 4)");
    std::stable_sort(limbs.begin(), limbs.end(), [](const Limb& a, const Limb& b) { return a.lowest < b.lowest; });
    f.limbs[0] = limbs[0];
    f.limbs[1] = limbs[1];
    std::vector<Limb> rest(limbs.begin() + 2, limbs.end());
    std::stable_sort(rest.begin(), rest.end(), [](const Limb& a, const Limb& b) { return a.reach > b.reach; });
    f.limbs[2] = rest[0];
    f.limbs[3] = rest[1];
    return f;
}

SourcePoint at(int j) { return SourcePoint{j, j, 0.0f}; }

// Leg roles (thigh, shin, foot, toe) of the limb, from its lowest leaf.
void map_leg(const Rest& r, const Limb& limb, int first_role, HumanoidChains& h, float& hip_height, float& floor) {
    int lowest_leaf = limb.leaves.front();
    for (int l : limb.leaves)
        if (r.extreme(l, false) < r.extreme(lowest_leaf, false)) lowest_leaf = l;
    std::vector<int> chain = path_down(*r.s, limb.attachment, lowest_leaf);
    // The hip: the first joint away from the attachment.
    size_t hip = 0;
    while (hip + 1 < chain.size() && r.dist(chain[hip], limb.attachment) < 1e-4f * (limb.reach + 1e-6f)) ++hip;
    floor = limb.lowest;
    const float top = r.height(chain[hip]);
    size_t ankle = hip + 1;
    while (ankle + 1 < chain.size() && r.height(chain[ankle]) - floor > 0.3f * (top - floor)) ++ankle;
    if (ankle >= chain.size() || ankle < hip + 2) {
        // Too few joints for hip, knee and ankle.
        throw ImportError("", 0, "leg '" + r.s->joint_names[static_cast<size_t>(limb.start)] + "' has fewer than three joints above its foot");
    }
    size_t knee = hip + 1;
    const float mid = 0.5f * (top + r.height(chain[ankle]));
    for (size_t k = hip + 1; k < ankle; ++k)
        if (std::abs(r.height(chain[k]) - mid) < std::abs(r.height(chain[knee]) - mid)) knee = k;
    const int j_hip = chain[hip], j_knee = chain[knee], j_ankle = chain[ankle];
    const int j_ball = ankle + 1 < chain.size() ? chain[ankle + 1] : j_ankle;
    int toe_end = ankle + 2 < chain.size() ? chain[ankle + 2] : r.end_site_of(j_ball);
    hip_height = top;
    h.joint[static_cast<size_t>(first_role)] = j_hip;
    h.from[static_cast<size_t>(first_role)] = at(j_hip);
    h.to[static_cast<size_t>(first_role)] = at(j_knee);
    h.joint[static_cast<size_t>(first_role + 1)] = j_knee;
    h.from[static_cast<size_t>(first_role + 1)] = at(j_knee);
    h.to[static_cast<size_t>(first_role + 1)] = at(j_ankle);
    h.joint[static_cast<size_t>(first_role + 2)] = j_ankle;
    h.from[static_cast<size_t>(first_role + 2)] = at(j_ankle);
    if (j_ball == j_ankle) {
        const int end = r.end_site_of(j_ankle);
        if (end < 0) throw ImportError("", 0, "foot '" + r.s->joint_names[static_cast<size_t>(j_ankle)] + "' has no toe joint or end site");
        h.to[static_cast<size_t>(first_role + 2)] = at(end);
        h.joint[static_cast<size_t>(first_role + 3)] = j_ankle;
        h.from[static_cast<size_t>(first_role + 3)] = at(j_ankle);
        h.to[static_cast<size_t>(first_role + 3)] = at(end);
        return;
    }
    h.to[static_cast<size_t>(first_role + 2)] = at(j_ball);
    if (toe_end < 0 || r.dist(toe_end, j_ball) < 1e-6f) toe_end = -1;
    h.joint[static_cast<size_t>(first_role + 3)] = toe_end < 0 ? j_ankle : j_ball;
    h.from[static_cast<size_t>(first_role + 3)] = at(toe_end < 0 ? j_ankle : j_ball);
    h.to[static_cast<size_t>(first_role + 3)] = at(toe_end < 0 ? j_ball : toe_end);
}

// Deepest common ancestor of the limb's leaves: the wrist.
int common_ancestor(const Skeleton& s, const std::vector<int>& leaves) {
    int c = leaves.front();
    for (int l : leaves) {
        std::vector<int> up;
        for (int j = l; j != kNoParent; j = s.parents[static_cast<size_t>(j)]) up.push_back(j);
        while (std::find(up.begin(), up.end(), c) == up.end()) c = s.parents[static_cast<size_t>(c)];
    }
    return c;
}

void map_arm(const Rest& r, const Limb& limb, int first_role, HumanoidChains& h) {
    const int wrist = common_ancestor(*r.s, limb.leaves);
    std::vector<int> chain = path_down(*r.s, limb.attachment, wrist);
    const float eps = 1e-4f * (limb.reach + 1e-6f);
    // Back from the wrist: the elbow and the shoulder are the previous joints
    // that are not where the next one is.
    int w = static_cast<int>(chain.size()) - 1;
    int e = w - 1;
    while (e >= 0 && r.dist(chain[static_cast<size_t>(e)], wrist) < eps) --e;
    int sh = e - 1;
    while (sh >= 0 && r.dist(chain[static_cast<size_t>(sh)], chain[static_cast<size_t>(e)]) < eps) --sh;
    if (e < 0 || sh < 0)
        throw ImportError("", 0, "arm '" + r.s->joint_names[static_cast<size_t>(limb.start)] + "' has fewer than three joints down to its wrist '" +
                                     r.s->joint_names[static_cast<size_t>(wrist)] + "'");
    int cl = sh - 1;
    while (cl >= 0 && r.dist(chain[static_cast<size_t>(cl)], chain[static_cast<size_t>(sh)]) < eps) --cl;
    const int j_sh = chain[static_cast<size_t>(sh)], j_el = chain[static_cast<size_t>(e)];
    const int j_cl = cl >= 0 ? chain[static_cast<size_t>(cl)] : limb.attachment;
    // The hand's end: toward the farthest leaf point.
    int far = -1;
    float far_d = -1.0f;
    for (int l : limb.leaves) {
        const int es = r.end_site_of(l);
        const int pt = es >= 0 ? es : l;
        if (r.dist(pt, wrist) > far_d) {
            far_d = r.dist(pt, wrist);
            far = pt;
        }
    }
    if (far < 0 || far_d < eps) throw ImportError("", 0, "hand '" + r.s->joint_names[static_cast<size_t>(wrist)] + "' has no length");
    const size_t b = static_cast<size_t>(first_role);
    h.joint[b] = j_cl;
    h.from[b] = at(j_cl);
    h.to[b] = at(j_sh);
    h.joint[b + 1] = j_sh;
    h.from[b + 1] = at(j_sh);
    h.to[b + 1] = at(j_el);
    h.joint[b + 2] = j_el;
    h.from[b + 2] = at(j_el);
    h.to[b + 2] = at(wrist);
    h.joint[b + 3] = wrist;
    h.from[b + 3] = at(wrist);
    h.to[b + 3] = at(far);
}

// The spine roles: pelvis, spine_01..03 spread by arc length over the source's
// root → chest path; neck from the joint above the chest to the head joint.
void map_spine(const Rest& r, const Found& f, HumanoidChains& h, const std::string& file) {
    const auto index_on_spine = [&](int j) {
        return static_cast<int>(std::find(f.spine.begin(), f.spine.end(), j) - f.spine.begin());
    };
    const int chest_i = std::max(index_on_spine(f.limbs[2].attachment), index_on_spine(f.limbs[3].attachment));
    const int head_top = r.end_site_of(f.head_leaf) >= 0 ? r.end_site_of(f.head_leaf) : f.head_leaf;
    const float leg = std::max(h.source_leg_length, 1e-6f);
    int head_i = static_cast<int>(f.spine.size()) - 1;
    while (head_i > chest_i + 1 && r.dist(f.spine[static_cast<size_t>(head_i)], head_top) < 0.05f * leg) --head_i;
    if (head_i <= chest_i)
        not_humanoid(file, "the arms hang from '" + r.s->joint_names[static_cast<size_t>(f.spine[static_cast<size_t>(chest_i)])] +
                               "', which is not below the head");
    const int neck_i = chest_i + 1 < head_i ? chest_i + 1 : chest_i;
    const int chest = f.spine[static_cast<size_t>(chest_i)];
    std::vector<float> arc(static_cast<size_t>(chest_i) + 1, 0.0f);
    for (int k = 1; k <= chest_i; ++k)
        arc[static_cast<size_t>(k)] = arc[static_cast<size_t>(k - 1)] + r.dist(f.spine[static_cast<size_t>(k - 1)], f.spine[static_cast<size_t>(k)]);
    const auto point_at = [&](float fraction, int& segment) {
        const float s = fraction * arc.back();
        int k = 0;
        while (k + 1 < chest_i && arc[static_cast<size_t>(k + 1)] <= s) ++k;
        segment = k;
        if (chest_i == 0) return at(chest);
        const float len = arc[static_cast<size_t>(k + 1)] - arc[static_cast<size_t>(k)];
        const float t = len > 0.0f ? std::clamp((s - arc[static_cast<size_t>(k)]) / len, 0.0f, 1.0f) : 0.0f;
        return SourcePoint{f.spine[static_cast<size_t>(k)], f.spine[static_cast<size_t>(k + 1)], t};
    };
    const float fractions[4] = {0.0f, h.spine_fractions[0], h.spine_fractions[1], 1.0f};
    for (int role = kPelvis; role <= kSpine2; ++role) {
        int seg_a = 0, seg_b = 0;
        h.from[static_cast<size_t>(role)] = point_at(fractions[role], seg_a);
        h.to[static_cast<size_t>(role)] = point_at(fractions[role + 1], seg_b);
        int mid = 0;
        point_at(0.5f * (fractions[role] + fractions[role + 1]), mid);
        h.joint[static_cast<size_t>(role)] = role == kPelvis ? f.spine.front() : f.spine[static_cast<size_t>(mid)];
    }
    h.joint[kSpine3] = chest;
    h.from[kSpine3] = at(chest);
    h.to[kSpine3] = at(f.spine[static_cast<size_t>(neck_i)]);
    h.joint[kNeck] = f.spine[static_cast<size_t>(neck_i)];
    h.from[kNeck] = at(f.spine[static_cast<size_t>(neck_i)]);
    h.to[kNeck] = at(f.spine[static_cast<size_t>(head_i)]);
    h.joint[kHead] = f.spine[static_cast<size_t>(head_i)];
    h.from[kHead] = at(f.spine[static_cast<size_t>(head_i)]);
    h.to[kHead] = at(head_top);
    if (neck_i == chest_i) h.to[kSpine3] = at(f.spine[static_cast<size_t>(head_i)]);
}

// Which of the two legs is the left one: +1 leg A, −1 leg B, from root travel
// (the character walks forward) or, when the root barely travels, the toes.
int left_leg_by_geometry(const Clip& clip, const Rest& r, const HumanoidChains& h, std::string& how) {
    const int hip_a = h.joint[kThighL], hip_b = h.joint[kThighR];
    const ModelFrames m = model_frames(clip);
    double vote = 0.0, travel = 0.0;
    for (int f = 1; f < clip.frame_count; ++f) {
        const vec3 l = m.position(f, hip_a) - m.position(f, hip_b);
        const vec3 forward = glm::cross(vec3(l.x, 0.0f, l.z), vec3(0, 1, 0));  // if A is left
        const vec3 v = m.position(f, 0) - m.position(f - 1, 0);
        const vec3 vh(v.x, 0.0f, v.z);
        vote += static_cast<double>(glm::dot(forward, vh)) / static_cast<double>(glm::length(l) + 1e-12f);
        travel += static_cast<double>(glm::length(vh));
    }
    if (travel > 0.5 * static_cast<double>(h.source_leg_length) && std::abs(vote) > 0.25 * travel) {
        how = "root travel";
        return vote > 0.0 ? 1 : -1;
    }
    const vec3 l = r.p[static_cast<size_t>(hip_a)] - r.p[static_cast<size_t>(hip_b)];
    const vec3 forward = glm::cross(vec3(l.x, 0.0f, l.z), vec3(0, 1, 0));
    vec3 toes(0.0f);
    for (int role : {kFootL, kFootR}) {
        const SourcePoint a = h.from[static_cast<size_t>(role)], b = h.to[static_cast<size_t>(role)];
        toes += r.p[static_cast<size_t>(b.a)] - r.p[static_cast<size_t>(a.a)];
    }
    how = "toes";
    return glm::dot(forward, vec3(toes.x, 0.0f, toes.z)) >= 0.0f ? 1 : -1;
}

int name_vote(const Skeleton& s, const HumanoidChains& h, int first_role, int roles) {
    int vote = 0;
    for (int k = 0; k < roles; ++k) vote += side_of_name(s.joint_names[static_cast<size_t>(h.joint[static_cast<size_t>(first_role + k)])]);
    return vote;
}

void swap_roles(HumanoidChains& h, int left_first, int right_first, int count) {
    for (int k = 0; k < count; ++k) {
        std::swap(h.joint[static_cast<size_t>(left_first + k)], h.joint[static_cast<size_t>(right_first + k)]);
        std::swap(h.from[static_cast<size_t>(left_first + k)], h.from[static_cast<size_t>(right_first + k)]);
        std::swap(h.to[static_cast<size_t>(left_first + k)], h.to[static_cast<size_t>(right_first + k)]);
    }
}

void decide_sides(const Clip& clip, const Rest& r, HumanoidChains& h, Found& f) {
    const int leg = left_leg_by_geometry(clip, r, h, h.side_from);
    if (leg < 0) {
        swap_roles(h, kThighL, kThighR, 4);
        std::swap(f.limbs[0], f.limbs[1]);
    }
    // The left arm is the one on the left hip's side.
    const vec3 lateral = r.p[static_cast<size_t>(h.joint[kThighL])] - r.p[static_cast<size_t>(h.joint[kThighR])];
    const vec3 arms = r.p[static_cast<size_t>(h.joint[kUpperArmL])] - r.p[static_cast<size_t>(h.joint[kUpperArmR])];
    if (glm::dot(vec3(lateral.x, 0, lateral.z), vec3(arms.x, 0, arms.z)) < 0.0f) {
        swap_roles(h, kClavicleL, kClavicleR, 4);
        std::swap(f.limbs[2], f.limbs[3]);
    }
    // Names confirm or override: a chain whose names say the other side wins.
    const Skeleton& s = clip.skeleton;
    const int legs = name_vote(s, h, kThighL, 4) - name_vote(s, h, kThighR, 4);
    const int arm_votes = name_vote(s, h, kClavicleL, 4) - name_vote(s, h, kClavicleR, 4);
    if (legs < 0) {
        swap_roles(h, kThighL, kThighR, 4);
        h.names_agree = false;
        h.notes.push_back("the legs' names say left and right the other way round than " + h.side_from + ": names win");
    }
    if (arm_votes < 0) {
        swap_roles(h, kClavicleL, kClavicleR, 4);
        h.names_agree = false;
        h.notes.push_back("the arms' names say left and right the other way round than the hips: names win");
    }
    if (!h.names_agree) h.side_from = "names";
}

const std::array<int, kRoleCount>& child_roles() {
    static const std::array<int, kRoleCount> kChild = {kSpine1, kSpine2, kSpine3, kNeck, kHead, -1,
                                                       kUpperArmL, kForearmL, kHandL, -1,
                                                       kUpperArmR, kForearmR, kHandR, -1,
                                                       kShinL, kFootL, kToeL, -1,
                                                       kShinR, kFootR, kToeR, -1};
    return kChild;
}

void apply_map(const Skeleton& s, const RetargetMap& map, HumanoidChains& h) {
    const auto& names = role_names();
    for (size_t i = 0; i < map.roles.size(); ++i) {
        // Plain references, not a structured binding: Clang 14 cannot capture a
        // structured binding in the lambda below (C++20 allows it; CI builds with Clang 14).
        const auto& role_name = map.roles[i].first;
        const auto& joint_name = map.roles[i].second;
        const int role = static_cast<int>(std::find_if(names.begin(), names.end(), [&](const char* n) { return role_name == n; }) - names.begin());
        const int j = s.find(joint_name);
        if (j < 0)
            throw ImportError(map.origin, map.lines[i], "retarget." + role_name + ": no joint named '" + joint_name + "' in the skeleton");
        h.joint[static_cast<size_t>(role)] = j;
        h.from[static_cast<size_t>(role)] = at(j);
        for (int p = 0; p < kRoleCount; ++p)
            if (child_roles()[static_cast<size_t>(p)] == role) h.to[static_cast<size_t>(p)] = at(j);
        h.notes.push_back("retarget." + role_name + " = '" + joint_name + "' (" + map.origin + ")");
    }
}

}  // namespace

int child_role(int r) { return r >= 0 && r < kRoleCount ? child_roles()[static_cast<size_t>(r)] : -1; }

// +1 left, −1 right, 0 unknown, from the common conventions: "Left…"/"Right…"
// (CMU BVH, Mixamo after its "mixamorig:" prefix), "…_l"/"….L", "LHipJoint"
// (a capital L or R before a capital), and CMU ASF's "lfemur", "rtibia", ...
int side_of_name(const std::string& full) {
    const size_t colon = full.find_last_of(':');
    const std::string name = colon == std::string::npos ? full : full.substr(colon + 1);
    const std::string n = lower(name);
    if (n.find("left") != std::string::npos) return 1;
    if (n.find("right") != std::string::npos) return -1;
    if (n.size() > 2) {
        const std::string tail = n.substr(n.size() - 2);
        if (tail == "_l" || tail == ".l") return 1;
        if (tail == "_r" || tail == ".r") return -1;
    }
    if (name.size() > 1 && (name[0] == 'L' || name[0] == 'R') && name[1] >= 'A' && name[1] <= 'Z')
        return name[0] == 'L' ? 1 : -1;
    static const char* const kCmu[] = {"hipjoint", "femur", "tibia", "foot", "toes", "clavicle",
                                       "humerus", "radius", "wrist", "hand", "fingers", "thumb"};
    if (n.size() > 1 && (n[0] == 'l' || n[0] == 'r'))
        for (const char* word : kCmu)
            if (n.substr(1) == word) return n[0] == 'l' ? 1 : -1;
    return 0;
}

const std::array<const char*, kRoleCount>& role_names() {
    static const std::array<const char*, kRoleCount> kNames = {
        "pelvis", "spine_01", "spine_02", "spine_03", "neck", "head",
        "clavicle_l", "upperarm_l", "forearm_l", "hand_l",
        "clavicle_r", "upperarm_r", "forearm_r", "hand_r",
        "thigh_l", "shin_l", "foot_l", "toe_l",
        "thigh_r", "shin_r", "foot_r", "toe_r"};
    return kNames;
}

HumanoidChains detect_humanoid(const Clip& clip, const std::string& file, const RetargetMap* map,
                               std::array<float, 2> spine_fractions) {
    const Rest r = make_rest(clip.skeleton);
    HumanoidChains h;
    h.spine_fractions = spine_fractions;
    Found f = find_limbs(r, file);
    float hip_a = 0, hip_b = 0, floor_a = 0, floor_b = 0;
    try {
        map_leg(r, f.limbs[0], kThighL, h, hip_a, floor_a);
        map_leg(r, f.limbs[1], kThighR, h, hip_b, floor_b);
        h.source_floor = std::min(floor_a, floor_b);
        h.source_leg_length = 0.5f * (hip_a + hip_b) - h.source_floor;
        if (!(h.source_leg_length > 0.0f)) not_humanoid(file, "the legs have no height at rest");
        map_arm(r, f.limbs[2], kClavicleL, h);
        map_arm(r, f.limbs[3], kClavicleR, h);
    } catch (const ImportError& e) {
        not_humanoid(file, e.message());
    }
    map_spine(r, f, h, file);
    decide_sides(clip, r, h, f);
    h.effectors = {f.head_leaf, f.limbs[0].leaves.front(), f.limbs[1].leaves.front(), common_ancestor(clip.skeleton, f.limbs[2].leaves),
                   common_ancestor(clip.skeleton, f.limbs[3].leaves)};
    h.effectors[1] = h.joint[kToeL];
    h.effectors[2] = h.joint[kToeR];
    h.effectors[3] = h.joint[kHandL];
    h.effectors[4] = h.joint[kHandR];
    if (map) apply_map(clip.skeleton, *map, h);
    return h;
}

RetargetMap parse_retarget_map(const std::string& text, const std::string& origin, bool allow_other_tables) {
    RetargetMap map;
    map.origin = origin;
    toml::table doc;
    try {
        doc = toml::parse(text, origin);
    } catch (const toml::parse_error& e) {
        throw ImportError(origin, static_cast<int>(e.source().begin.line), "TOML syntax error: " + std::string(e.description()));
    }
    const auto line_of = [](const toml::node& n) { return static_cast<int>(n.source().begin.line); };
    const toml::table* table = nullptr;
    for (const auto& [key, node] : doc) {
        if (key.str() == "retarget" && node.as_table()) {
            table = node.as_table();
        } else if (!allow_other_tables) {
            throw ImportError(origin, line_of(node), "unknown entry '" + std::string(key.str()) + "' (a map file holds one table, [retarget])");
        }
    }
    if (!table) {
        if (allow_other_tables) return map;
        throw ImportError(origin, 1, "no [retarget] table (expected [retarget] with ROLE = \"JOINT\" lines, docs/retarget.md)");
    }
    const auto& names = role_names();
    for (const auto& [k, v] : *table) {
        const std::string key(k.str());
        const auto* s = v.as_string();
        if (key == "up") {
            if (!s || (s->get() != "y" && s->get() != "z"))
                throw ImportError(origin, line_of(v), "retarget.up: expected \"y\" or \"z\" (the source's up axis)");
            map.up = s->get();
            continue;
        }
        if (std::find_if(names.begin(), names.end(), [&](const char* n) { return key == n; }) == names.end()) {
            std::string known;
            for (const char* n : names) known += (known.empty() ? "" : ", ") + std::string(n);
            throw ImportError(origin, line_of(v), "retarget." + key + ": unknown role (expected up or one of " + known + ")");
        }
        if (!s || s->get().empty())
            throw ImportError(origin, line_of(v), "retarget." + key + ": expected the source joint's name as a non-empty string");
        for (const auto& [seen, joint] : map.roles)
            if (seen == key) throw ImportError(origin, line_of(v), "retarget." + key + ": given twice");
        map.roles.emplace_back(key, s->get());
        map.lines.push_back(line_of(v));
    }
    return map;
}

}  // namespace marionette::retarget
