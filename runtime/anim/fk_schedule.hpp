#pragma once
// The order forward kinematics solves a skeleton's joints in when it solves two
// at a time (fk::local_to_model_pairs, runtime/anim/local_to_model.hpp): built
// once per skeleton, read by LocalToModelJob and GaitPoseJob on every run.
//
// Roots are copied first. Every other joint sits in one half of one slot; the
// two joints of a slot are independent (neither is the other's parent, both
// parents are in earlier slots or roots), so one 256-bit vector solves both.
// A joint whose parent was the previous slot's joint in the same half takes
// its parent from registers ("chained"): in a limb that is every joint after
// the first, and it keeps the parent off the store-to-load path.
//
// How the slots are chosen (greedy list scheduling, deterministic): each half
// continues its own chain when the joint it just solved has a child ready,
// otherwise takes the ready joint with the longest chain of descendants still
// to solve (lowest index on a tie); a slot with one ready joint solves it in
// both halves. The puppet's 22 joints: 1 root and 11 slots (the fewest
// possible), 10 of them chained in at least one half and 6 in both.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace marionette {

struct FkPairSlot {
    // Byte offsets of the two joints (index * sizeof(quat), index * sizeof(vec3)),
    // and of their parents; half 1 repeats half 0 when the slot solves one joint.
    std::uint32_t rotation_offset[2];
    std::uint32_t position_offset[2];
    std::uint32_t parent_rotation_offset[2];
    std::uint32_t parent_position_offset[2];
    std::uint32_t chained;  // bit h: half h's parent is the previous slot's half h
};

class FkSchedule {
public:
    // The most joints a schedule covers. Building one scans the ready joints
    // once per slot (quadratic for a star-shaped skeleton), so a bound keeps a
    // huge imported skeleton from stalling its load: real ones have tens to a
    // few hundred joints, and without a schedule the one-joint kernel runs.
    static constexpr std::size_t kMaxJoints = 4096;

    FkSchedule() = default;  // covers no skeleton: matches() only an empty one
    // A schedule for these parents. When they are not in topological order or
    // exceed kMaxJoints, the schedule is empty and valid() is false, so every
    // job given it refuses to run (its validate() fails).
    explicit FkSchedule(std::span<const int> parents);

    bool valid() const { return valid_; }
    // True when this schedule was built from exactly these parents: a job's
    // validate() check, one comparison of the two arrays.
    bool matches(std::span<const int> parents) const;
    std::span<const int> parents() const { return parents_; }

    std::span<const std::uint32_t> root_rotation_offsets() const { return root_rotation_offsets_; }
    std::span<const std::uint32_t> root_position_offsets() const { return root_position_offsets_; }
    std::span<const FkPairSlot> slots() const { return slots_; }

private:
    bool valid_ = true;
    std::vector<int> parents_;
    std::vector<std::uint32_t> root_rotation_offsets_;
    std::vector<std::uint32_t> root_position_offsets_;
    std::vector<FkPairSlot> slots_;
};

}  // namespace marionette
