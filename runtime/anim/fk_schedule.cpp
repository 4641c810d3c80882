#include "runtime/anim/fk_schedule.hpp"

#include <algorithm>
#include <cstring>

#include "runtime/anim/pose_spans.hpp"

namespace marionette {

namespace {

constexpr std::size_t kNone = static_cast<std::size_t>(-1);

}  // namespace

FkSchedule::FkSchedule(std::span<const int> parents) {
    const std::size_t n = parents.size();
    if (n > kMaxJoints || !parents_in_topological_order(parents)) {
        valid_ = false;
        return;
    }
    parents_.assign(parents.begin(), parents.end());
    auto parent_of = [&](std::size_t j) { return static_cast<std::size_t>(parents[j]); };
    // Longest chain of descendants below each joint (itself included): the
    // priority of list scheduling, so the deepest limb is never left for last.
    std::vector<std::uint32_t> height(n, 1);
    for (std::size_t j = n; j-- > 0;)
        if (parents[j] != kNoParent) height[parent_of(j)] = std::max(height[parent_of(j)], height[j] + 1);
    // Children as index ranges into one array (parents are in order, so a
    // counting pass lists every joint's children in increasing index).
    std::vector<std::size_t> first_child(n + 1, 0), children(n);
    for (std::size_t j = 0; j < n; ++j)
        if (parents[j] != kNoParent) ++first_child[parent_of(j) + 1];
    for (std::size_t j = 0; j < n; ++j) first_child[j + 1] += first_child[j];
    {
        std::vector<std::size_t> fill(first_child.begin(), first_child.end() - 1);
        for (std::size_t j = 0; j < n; ++j)
            if (parents[j] != kNoParent) children[fill[parent_of(j)]++] = j;
    }
    auto rotation_offset = [](std::size_t j) { return static_cast<std::uint32_t>(j * 16); };
    auto position_offset = [](std::size_t j) { return static_cast<std::uint32_t>(j * 12); };

    std::vector<std::size_t> ready;  // solvable now: the parent is done
    for (std::size_t j = 0; j < n; ++j)
        if (parents[j] == kNoParent) {
            root_rotation_offsets_.push_back(rotation_offset(j));
            root_position_offsets_.push_back(position_offset(j));
            for (std::size_t c = first_child[j]; c < first_child[j + 1]; ++c) ready.push_back(children[c]);
        }
    auto better = [&](std::size_t a, std::size_t b) {  // a before b?
        return b == kNone || height[a] > height[b] || (height[a] == height[b] && a < b);
    };
    std::size_t previous[2] = {kNone, kNone};
    while (!ready.empty()) {
        std::size_t pick[2] = {kNone, kNone};
        // Each half continues its own chain first.
        for (int h = 0; h < 2; ++h) {
            if (previous[h] == kNone) continue;
            for (std::size_t r : ready)
                if (parent_of(r) == previous[h] && r != pick[0] && better(r, pick[h])) pick[h] = r;
        }
        for (int h = 0; h < 2; ++h) {
            if (pick[h] != kNone) continue;
            for (std::size_t r : ready)
                if (r != pick[0] && r != pick[1] && better(r, pick[h])) pick[h] = r;
        }
        if (pick[1] == kNone) pick[1] = pick[0];
        if (pick[0] == kNone) pick[0] = pick[1];
        FkPairSlot slot{};
        for (int h = 0; h < 2; ++h) {
            const std::size_t j = pick[h];
            slot.rotation_offset[h] = rotation_offset(j);
            slot.position_offset[h] = position_offset(j);
            slot.parent_rotation_offset[h] = rotation_offset(parent_of(j));
            slot.parent_position_offset[h] = position_offset(parent_of(j));
            if (parent_of(j) == previous[h]) slot.chained |= 1u << h;
        }
        slots_.push_back(slot);
        ready.erase(std::remove_if(ready.begin(), ready.end(), [&](std::size_t r) { return r == pick[0] || r == pick[1]; }),
                    ready.end());
        for (int h = 0; h < 2; ++h) {
            if (h == 1 && pick[1] == pick[0]) break;
            for (std::size_t c = first_child[pick[h]]; c < first_child[pick[h] + 1]; ++c) ready.push_back(children[c]);
        }
        previous[0] = pick[0];
        previous[1] = pick[1];
    }
}

bool FkSchedule::matches(std::span<const int> parents) const {
    return valid_ && parents.size() == parents_.size() &&
           (parents.empty() || std::memcmp(parents.data(), parents_.data(), parents.size() * sizeof(int)) == 0);
}

}  // namespace marionette
