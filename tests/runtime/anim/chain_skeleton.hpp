#pragma once
// A three-joint chain along +Y, shared by the skeleton, clip and FK tests.
#include "runtime/anim/skeleton.hpp"

namespace marionette::test {

inline Skeleton chain() {
    Skeleton s;
    s.joint_names = {"root", "mid", "tip"};
    s.parents = {kNoParent, 0, 1};
    s.rest_offsets = {vec3(1, 0, 0), vec3(0, 2, 0), vec3(0, 3, 0)};
    return s;
}

}  // namespace marionette::test
