#pragma once
// `clip fill-eval` (docs/fill.md): leave each clip out of a database built from
// the others, hide a joint group over seeded random gaps of each length, fill with
// every method and measure the hidden joints' position error against the truth
// and the continuity at the gap's borders.
#include <cstdint>
#include <string>
#include <vector>

#include "graph_builder/clip_fill.hpp"

namespace marionette::offline {

struct FillEvalOptions {
    std::string hide;                  // --hide text (joints or groups)
    std::vector<double> gaps_s = {0.25, 0.5, 1.0, 2.0, 4.0};
    std::uint64_t seed = 1;
    int trials = 3;                    // random gaps per clip and gap length
    FillOptions fill;                  // method is set per row
};

struct FillEvalRow {
    FillMethod method = FillMethod::graph;
    double gap_s = 0.0;
    int cases = 0;
    double mean_cm = 0.0;              // over every case, gap frame and moving hidden point
    double worst_cm = 0.0;             // the largest of those
    double continuity_mean = 0.0;      // border move / the clip's 95th-percentile move
    double continuity_worst = 0.0;
};

// One clip's share of a row (which clips the error comes from).
struct FillEvalClipRow {
    int clip = 0;                      // index into the clips given
    FillMethod method = FillMethod::graph;
    double gap_s = 0.0;
    int cases = 0;
    double mean_cm = 0.0;
};

struct FillEvalResult {
    std::vector<FillEvalRow> rows;     // method-major: graph, slerp, hold; then gap lengths in order
    std::vector<FillEvalClipRow> per_clip;  // clip-major, then gap length, then method; clips too short left out
    int skipped = 0;                   // (clip, gap length) pairs with a clip too short for the gap
    double cm_per_unit = 1.0;
};

// Centimetres per file unit: CMU ASF lengths are inches scaled by `:units length`
// (2.54 / 0.45 cm); BVH files are taken as centimetres.
double centimetres_per_unit(const Clip& clip);

// Every clip must share the first one's skeleton (throws ImportError naming the
// clip otherwise) and there must be at least two. `extra` clips (on that
// skeleton too: retarget them first, `retarget_fill_clip`) join every
// leave-one-out database and are never filled themselves.
FillEvalResult evaluate_fill(const std::vector<Clip>& clips, const std::vector<std::string>& names,
                             const FillEvalOptions& options, const std::vector<Clip>& extra = {});

}  // namespace marionette::offline
