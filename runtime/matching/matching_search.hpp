#pragma once
// Nearest-frame search over a MatchingDatabase: the frame whose normalised
// features are closest (squared Euclidean distance, summed in feature order in
// float) to a normalised query, among the searchable frames. Ties go to the
// lower frame index, so the answer never depends on the build or the order the
// frames are visited in.
//
// search_matching_brute_force visits every frame. search_matching_accelerated
// gives exactly the same answer faster: it skips a run of frames when the
// distance from the query to the run's bounding box (large boxes of
// kMatchLargeBox frames, then small ones of kMatchSmallBox) already exceeds the
// best cost, and stops summing a frame's distance once it does (Holden's
// Motion-Matching code does the same). Both are exact: a box's distance is a
// float sum of terms no larger than any of its frames' terms, in the same order,
// so it never exceeds their costs, and a box is skipped only when it is
// strictly worse, so a tie still reaches the frame comparison. Neither allocates.
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
