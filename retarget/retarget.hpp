#pragma once
// Retargeting any humanoid clip onto the puppet's skeleton (docs/retarget.md).
//
// Per mapped bone, rest-direction alignment: the puppet bone's world rotation is
// the source bone's world rotation change since its rest pose, applied after the
// rotation that turns the puppet's rest direction onto the source's rest
// direction, then swung so the bone points exactly where the source's does. So
// T-pose, A-pose and bones along other axes need no names. Root motion is
// scaled by leg length; feet the source plants (low and slow) are pinned on the
// puppet with two-bone IK. Offline code: allocates, throws ImportError.
#include <string>
#include <vector>

#include "retarget/humanoid.hpp"
#include "runtime/anim/clip.hpp"

namespace marionette::retarget {

struct RetargetOptions {
    const RetargetMap* map = nullptr;
    // Contacts, in puppet leg lengths: a foot point within contact_height of its
    // lowest height over the clip, moving slower than contact_speed (leg lengths
    // per second) horizontally, is planted.
    float contact_height = 0.06f;
    float contact_speed = 0.4f;
    float min_contact_s = 0.05f;   // shorter runs are not contacts
    float release_s = 0.1f;        // after a contact, the foot eases back to the clip's path
    bool fix_contacts = true;      // false: direction transfer only (for measuring what IK adds)
};

struct BoneAgreement {
    std::string puppet_joint;
    std::string source_joint;    // the source joint whose rotation drives it
    double mean_cos = 0.0;       // mean over frames of cos(puppet bone, source bone) in world space
    double min_cos = 0.0;
};

struct ContactReport {
    int runs = 0;                // contact runs over both feet
    int frames = 0;              // foot-frames in contact
    double max_drift_m = 0.0;    // largest distance a pinned puppet point moves within its run
    double mean_drift_m = 0.0;   // mean over runs of each run's largest distance
    double max_drift_before_ik_m = 0.0;  // the same without the IK clean-up
    double max_root_drop_m = 0.0;         // the largest lowering of the pelvis the IK needed
};

struct RetargetResult {
    Clip clip;                   // on the puppet's skeleton, metres, the source's rate
    HumanoidChains chains;
    std::vector<BoneAgreement> bones;  // one per puppet joint
    ContactReport contacts;
    double scale = 1.0;          // puppet leg length / source leg length (source units)
    // Metres the pelvis was lowered (negative: raised) so the puppet's feet stand
    // on the ground where the source's did: the puppet's legs need not have the
    // source's proportions, so its feet at the source's scaled hip height float or sink.
    double ground_shift_m = 0.0;
    // Per frame and foot (0 left, 1 right): 0 free, 1 heel (ankle) planted, 2 ball planted.
    std::vector<unsigned char> contact_kind;
};

// Retargets `source` onto `puppet` (a skeleton of make_puppet_skeleton's
// layout: the roles of retarget/humanoid.hpp are its joints). `file` names the
// source in errors. Throws ImportError when no humanoid is found.
RetargetResult retarget_clip(const Clip& source, const Skeleton& puppet, const std::string& file,
                             const RetargetOptions& options = {});

// True when `skeleton` has the puppet's joint names and hierarchy (then a clip
// needs no retargeting).
bool is_puppet_skeleton(const Skeleton& skeleton, const Skeleton& puppet);

}  // namespace marionette::retarget
