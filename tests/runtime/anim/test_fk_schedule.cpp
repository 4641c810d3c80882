// FkSchedule (runtime/anim/fk_schedule.hpp): the order the pair kernel solves
// joints in, checked as properties on generated skeletons of every shape (fixed
// seed: chains, stars, forests, near and random parents, 1 to 300 joints), on
// the puppet, and as LocalToModelJob's refusals.
#include <catch2/catch.hpp>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "runtime/anim/fk_schedule.hpp"
#include "runtime/anim/skeleton.hpp"
#include "runtime/gait/puppet.hpp"
#include "runtime/gait/gait_config.hpp"

using namespace marionette;

namespace {

std::vector<int> generated_parents(std::mt19937& rng, std::size_t n) {
    std::vector<int> parents(n);
    const std::uint32_t shape = static_cast<std::uint32_t>(rng()) % 5;
    for (std::size_t i = 0; i < n; ++i) {
        const std::uint32_t r = static_cast<std::uint32_t>(rng());
        if (i == 0) parents[i] = kNoParent;
        else if (shape == 0) parents[i] = static_cast<int>(i - 1);
        else if (shape == 1) parents[i] = 0;
        else if (shape == 2) parents[i] = r % 8 == 0 ? kNoParent : static_cast<int>(r % i);
        else if (shape == 3) parents[i] = static_cast<int>(i - 1 - r % (i < 4 ? i : 4));
        else parents[i] = static_cast<int>(r % i);
    }
    return parents;
}

// Every property the pair kernel relies on; "" when all hold, else which not.
std::string check_schedule(const std::vector<int>& parents, const FkSchedule& schedule) {
    const std::size_t n = parents.size();
    if (!schedule.valid() || !schedule.matches(parents)) return "not valid for its own parents";
    std::vector<int> solved_in(n, -2);  // -1: a root; k: slot k
    const auto roots = schedule.root_rotation_offsets();
    if (roots.size() != schedule.root_position_offsets().size()) return "root offset lists differ in length";
    for (std::size_t r = 0; r < roots.size(); ++r) {
        const std::size_t j = roots[r] / 16;
        if (roots[r] % 16 != 0 || j >= n || schedule.root_position_offsets()[r] != j * 12) return "bad root offset";
        if (parents[j] != kNoParent) return "joint " + std::to_string(j) + " listed as a root";
        if (solved_in[j] != -2) return "root listed twice";
        solved_in[j] = -1;
    }
    const auto slots = schedule.slots();
    std::size_t previous[2] = {n, n};
    for (std::size_t k = 0; k < slots.size(); ++k) {
        const FkPairSlot& s = slots[k];
        std::size_t joint[2];
        for (int h = 0; h < 2; ++h) {
            joint[h] = s.rotation_offset[h] / 16;
            if (s.rotation_offset[h] % 16 != 0 || joint[h] >= n || s.position_offset[h] != joint[h] * 12)
                return "slot " + std::to_string(k) + ": bad offsets";
            const int p = parents[joint[h]];
            if (p == kNoParent) return "slot " + std::to_string(k) + " solves a root";
            const std::size_t parent = static_cast<std::size_t>(p);
            if (s.parent_rotation_offset[h] != parent * 16 || s.parent_position_offset[h] != parent * 12)
                return "slot " + std::to_string(k) + ": parent offsets are not the parent's";
            if (solved_in[parent] == -2 || solved_in[parent] >= static_cast<int>(k))
                return "slot " + std::to_string(k) + ": a parent is not solved before it";
            const bool chained = (s.chained >> h) & 1u;
            if (chained != (parent == previous[h])) return "slot " + std::to_string(k) + ": wrong chained bit";
        }
        if (s.chained > 3u) return "chained has stray bits";
        for (int h = 0; h < 2; ++h) {
            if (h == 1 && joint[1] == joint[0]) break;  // one joint, in both halves
            if (solved_in[joint[h]] != -2) return "joint " + std::to_string(joint[h]) + " solved twice";
            solved_in[joint[h]] = static_cast<int>(k);
        }
        previous[0] = joint[0];
        previous[1] = joint[1];
    }
    for (std::size_t j = 0; j < n; ++j)
        if (solved_in[j] == -2) return "joint " + std::to_string(j) + " never solved";
    return "";
}

}  // namespace

TEST_CASE("FkSchedule: every joint once, parents first, halves independent, on generated skeletons",
          "[skeleton][fk]") {
    std::mt19937 rng(31337u);
    std::size_t pairs = 0, slots = 0;
    for (int k = 0; k < 1500; ++k) {
        const std::size_t n = k < 8 ? static_cast<std::size_t>(k + 1) : 1 + rng() % (rng() % 4 == 0 ? 300 : 70);
        const std::vector<int> parents = generated_parents(rng, n);
        const FkSchedule schedule(parents);
        INFO("case " << k << ", " << n << " joints");
        REQUIRE(check_schedule(parents, schedule) == "");
        // Never more slots than joints to solve, and at least half as many.
        std::size_t roots = schedule.root_rotation_offsets().size();
        REQUIRE(schedule.slots().size() <= n - roots);
        REQUIRE(2 * schedule.slots().size() >= n - roots);
        for (const FkPairSlot& s : schedule.slots()) pairs += s.rotation_offset[0] != s.rotation_offset[1];
        slots += schedule.slots().size();
    }
    CHECK(pairs * 2 > slots);  // the generated shapes mostly allow two at a time
}

TEST_CASE("FkSchedule: the puppet's 21 non-root joints in 11 slots, limbs kept in one half", "[skeleton][fk]") {
    const Skeleton puppet = make_puppet_skeleton(GaitConfig{});
    const FkSchedule schedule(puppet.parents);
    REQUIRE(check_schedule(puppet.parents, schedule) == "");
    CHECK(schedule.root_rotation_offsets().size() == 1);
    CHECK(schedule.slots().size() == 11);  // ceil(21 / 2): the fewest possible
    std::size_t chained = 0;
    for (const FkPairSlot& s : schedule.slots()) chained += s.chained != 0;
    CHECK(chained >= 9);
}

TEST_CASE("FkSchedule: a chain is one joint per slot, each chained to the last", "[skeleton][fk]") {
    const std::vector<int> chain = {kNoParent, 0, 1, 2, 3};
    const FkSchedule schedule(chain);
    REQUIRE(check_schedule(chain, schedule) == "");
    REQUIRE(schedule.slots().size() == 4);
    for (std::size_t k = 1; k < 4; ++k) CHECK(schedule.slots()[k].chained == 3u);
}

TEST_CASE("FkSchedule: refuses parents out of order; matches only its own parents", "[skeleton][fk][job]") {
    CHECK_FALSE(FkSchedule(std::vector<int>{0}).valid());
    CHECK_FALSE(FkSchedule(std::vector<int>{kNoParent, 2, 0}).valid());
    CHECK_FALSE(FkSchedule(std::vector<int>{kNoParent, -2}).valid());
    std::vector<int> star(FkSchedule::kMaxJoints + 1, 0);
    star[0] = kNoParent;
    CHECK_FALSE(FkSchedule(star).valid());  // past the bound: no schedule, so no quadratic build
    star.pop_back();
    CHECK(FkSchedule(star).valid());
    CHECK_FALSE(FkSchedule(std::vector<int>{kNoParent, 0, 2}).matches(std::vector<int>{kNoParent, 0, 2}));
    CHECK(FkSchedule(std::vector<int>{}).matches(std::vector<int>{}));
    const std::vector<int> parents = {kNoParent, 0, 1, 0, 3};
    const FkSchedule schedule(parents);
    CHECK(schedule.matches(parents));
    CHECK_FALSE(schedule.matches(std::vector<int>{kNoParent, 0, 1, 0}));
    CHECK_FALSE(schedule.matches(std::vector<int>{kNoParent, 0, 1, 0, 3, 4}));
    CHECK_FALSE(schedule.matches(std::vector<int>{kNoParent, 0, 1, 1, 3}));

    // A job given a schedule of other parents refuses, and writes nothing.
    const std::vector<quat> local_rotations(5, quat_identity());
    const std::vector<vec3> local_translations(5, vec3(0.0f, 1.0f, 0.0f));
    std::vector<quat> model_rotations(5, quat_wxyz(7, 7, 7, 7));
    std::vector<vec3> model_positions(5, vec3(7.0f));
    const FkSchedule other(std::vector<int>{kNoParent, 0, 0, 0, 0});
    const FkSchedule refused(std::vector<int>{kNoParent, 3, 0, 0, 0});
    for (const FkSchedule* s : {&other, &refused}) {
        const LocalToModelJob job{parents, {local_rotations, local_translations}, {model_rotations, model_positions}, s};
        CHECK_FALSE(job.validate());
        CHECK_FALSE(job.run());
        CHECK(model_positions[4] == vec3(7.0f));
        CHECK(model_rotations[0] == quat_wxyz(7, 7, 7, 7));
    }
    const LocalToModelJob job{parents, {local_rotations, local_translations}, {model_rotations, model_positions}, &schedule};
    REQUIRE(job.run());
    CHECK(model_positions[4] == vec3(0.0f, 3.0f, 0.0f));  // root at 1, two more steps of 1
}
