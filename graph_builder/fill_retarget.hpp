#pragma once
// Database clips of other skeletons for `clip fill` (docs/fill.md): a clip is
// moved onto the filled clip's skeleton through the humanoid chains that
// retarget/ detects on both (the same rest-direction alignment the puppet
// retargeter uses, but onto any detected humanoid instead of the puppet).
// Offline code: allocates, throws ImportError naming the file.
#include <string>

#include "runtime/anim/clip.hpp"

namespace marionette::offline {

// `source` on `target.skeleton`: per humanoid role, the target joint's world
// rotation is the source joint's rotation change since its rest pose (turned
// from the source's rest facing to the target's), applied after the rotation
// that turns the target's rest bone direction onto the source's. Joints no
// role drives keep their rest rotation relative to their parent; the root's
// path is scaled by the ratio of leg lengths. `target` needs its motion only
// for chain detection (sides). Throws ImportError naming `source_file` (or
// `target_file`) when no humanoid is found in a skeleton.
Clip retarget_fill_clip(const Clip& source, const std::string& source_file, const Clip& target,
                        const std::string& target_file);

}  // namespace marionette::offline
