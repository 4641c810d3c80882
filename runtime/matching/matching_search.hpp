#pragma once
// Nearest-frame search over a MatchingDatabase: the frame whose normalised
// features are closest (squared Euclidean distance, summed in feature order in
// float) to a normalised query, among the searchable frames. Ties go to the
// lower frame index, so the answer never depends on the build or the order the
// frames are visited in.
//
// search_matching_brute_force visits every frame. search_matching_accelerated
// gives exactly the same answer faster, on the database's search layout (plain
// data built with it, matching_database.hpp): the searchable frames in k-d order
// under three levels of bounding boxes (512, 64 and 16 frames), 8 frames summed
// lane-parallel. It visits the top boxes nearest the query first, then the rest,
// and skips a box when a lower bound of its frames' costs is strictly worse than
// the best so far; a block of 8 frames is abandoned once all of them are. Every
// bound is a float sum, in feature order, of terms no larger than the frames'
// (all the features, or only the trajectory's), so it never exceeds a frame's
// cost; each frame's cost is the same float sum as matching_cost, bit for bit;
// so the result is the least (cost, frame index) whatever the visiting order,
// ties to the lower frame. Neither search allocates.
#include <cstdint>
#include <limits>
#include <span>

#include "runtime/matching/matching_database.hpp"

namespace marionette {

struct MatchingResult {
    std::int32_t frame = -1;
    float cost = std::numeric_limits<float>::infinity();
    // True when (cost, frame) is lexicographically smaller than the best.
    bool beaten_by(float c, std::int32_t f) const { return c < cost || (c == cost && f < frame); }
};

// The squared distance of one database frame to the query (the order both searches sum in).
float matching_cost(const MatchingDatabase& db, std::span<const float> query, int frame);

// `best` is a candidate already known (the current frame, say): the result is
// the better of it and the database's best. `query` holds kMatchFeatureCount values.
MatchingResult search_matching_brute_force(const MatchingDatabase& db, std::span<const float> query,
                                           MatchingResult best = {});
MatchingResult search_matching_accelerated(const MatchingDatabase& db, std::span<const float> query,
                                           MatchingResult best = {});

}  // namespace marionette
