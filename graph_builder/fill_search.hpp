#pragma once
// The graph method's search (docs/fill.md): the database segment whose joints
// best match the clip over a gap and a window on each side (Kovar distance, root
// aligned; visible joints inside the gap, every joint outside it), over a set of
// uniform time scales, then the best few refined by dynamic time warping.
#include <vector>

#include "graph_builder/clip_fill.hpp"

namespace marionette::offline {

struct FillMapping {
    FillMatch match;
    double query_t0 = 0.0;         // clip time of query frame 0
    double query_rate = 30.0;      // query frames per second (the database rate)
    std::vector<double> db_time;   // per query frame: time in the matched database clip
};

// Time in the matched database clip for a clip time `t` (linear between query frames).
double mapped_db_time(const FillMapping& mapping, double t);

// The best `options.blend_matches` DTW-refined matches, best first (empty when
// no database segment fits).
std::vector<FillMapping> search_fill_motion(const Clip& clip, const FillGap& gap, const FillDatabase& db,
                                            const FillOptions& options);

}  // namespace marionette::offline
