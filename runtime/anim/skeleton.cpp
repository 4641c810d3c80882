#include "runtime/anim/skeleton.hpp"

#include "runtime/anim/local_to_model.hpp"

#include <map>

namespace marionette {

int Skeleton::find(std::string_view name) const {
    for (int i = 0; i < joint_count(); ++i)
        if (joint_names[static_cast<size_t>(i)] == name) return i;
    return -1;
}

Outcome validate_skeleton(const Skeleton& s) {
    const size_t n = s.parents.size();
    if (s.joint_names.size() != n || s.rest_offsets.size() != n)
        return Outcome::failure("joint name, parent and offset arrays differ in size");
    if (n == 0) return Outcome::failure("skeleton has no joints");
    std::map<std::string_view, size_t> seen;
    for (size_t i = 0; i < n; ++i) {
        if (s.parents[i] != kNoParent && (s.parents[i] < 0 || static_cast<size_t>(s.parents[i]) >= i))
            return Outcome::failure("joint '" + s.joint_names[i] + "' has parent index " +
                                    std::to_string(s.parents[i]) + ", which is not an earlier joint");
        if (s.joint_names[i].empty()) return Outcome::failure("joint " + std::to_string(i) + " has an empty name");
        auto [it, inserted] = seen.emplace(s.joint_names[i], i);
        if (!inserted) return Outcome::failure("duplicate joint name '" + s.joint_names[i] + "'");
    }
    if (s.end_site_parents.size() != s.end_site_offsets.size())
        return Outcome::failure("end site parent and offset arrays differ in size");
    for (int p : s.end_site_parents)
        if (p < 0 || static_cast<size_t>(p) >= n) return Outcome::failure("end site has an invalid parent index");
    return Outcome::success();
}

Pose rest_pose(const Skeleton& s) {
    Pose pose;
    pose.local_rotations.assign(s.parents.size(), quat_identity());
    pose.local_translations = s.rest_offsets;
    return pose;
}

bool LocalToModelJob::validate() const {
    const size_t n = parents.size();
    return input.rotations.size() == n && input.translations.size() == n && output.rotations.size() >= n &&
           output.positions.size() >= n && fk::order_valid(parents, schedule);
}

bool LocalToModelJob::run() const {
    if (!validate()) return false;
    fk::local_to_model(parents, schedule, input, output);
    return true;
}

}  // namespace marionette
