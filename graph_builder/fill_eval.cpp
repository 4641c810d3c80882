#include "graph_builder/fill_eval.hpp"

#include <algorithm>
#include <cmath>

#include "runtime/errors/import_error.hpp"
#include "runtime/math/splitmix64.hpp"

namespace marionette::offline {

namespace {

// The gaps' positions, one splitmix64 stream per run.
struct SplitMix64 {
    std::uint64_t state;
    std::uint64_t next() { return splitmix64_next(state); }
};

double distance(vec3 a, vec3 b) {
    const double x = a.x - b.x, y = a.y - b.y, z = a.z - b.z;
    return std::sqrt(x * x + y * y + z * z);
}

// The points a hidden rotation moves: hidden joints under a hidden parent, and
// end sites of hidden joints (indices into a joints-then-end-sites row).
std::vector<size_t> moving_points(const Skeleton& s, const std::vector<bool>& hidden) {
    std::vector<size_t> out;
    for (int j = 0; j < s.joint_count(); ++j) {
        const int p = s.parents[static_cast<size_t>(j)];
        if (p != kNoParent && hidden[static_cast<size_t>(j)] && hidden[static_cast<size_t>(p)]) out.push_back(static_cast<size_t>(j));
    }
    for (size_t k = 0; k < s.end_site_parents.size(); ++k)
        if (hidden[static_cast<size_t>(s.end_site_parents[k])]) out.push_back(static_cast<size_t>(s.joint_count()) + k);
    return out;
}

// Largest move of the points between frames f − 1 and f, per frame (entry 0 is 0).
std::vector<double> frame_moves(const std::vector<vec3>& p, size_t row, const std::vector<size_t>& points, int frames) {
    std::vector<double> out(static_cast<size_t>(frames), 0.0);
    for (int f = 1; f < frames; ++f)
        for (size_t k : points)
            out[static_cast<size_t>(f)] = std::max(out[static_cast<size_t>(f)],
                                                   distance(p[static_cast<size_t>(f) * row + k], p[static_cast<size_t>(f - 1) * row + k]));
    return out;
}

double percentile95(std::vector<double> v) {
    if (v.size() < 2) return 0.0;
    v.erase(v.begin());
    std::sort(v.begin(), v.end());
    return v[static_cast<size_t>(0.95 * static_cast<double>(v.size() - 1))];
}

struct Accumulator {
    int cases = 0;
    double sum = 0.0, count = 0.0, worst = 0.0, cont_sum = 0.0, cont_worst = 0.0;
};

// One filled case against the truth: error over the gap, continuity at its borders.
void measure(const Clip& filled, const std::vector<vec3>& truth, const FillGap& g, const std::vector<size_t>& points,
             double p95, double cm, Accumulator& acc) {
    const int lo = std::max(0, g.first - 1), hi = std::min(filled.frame_count - 1, g.last + 1);
    const std::vector<vec3> p = model_positions_with_end_sites(filled, lo, hi);
    const size_t row = static_cast<size_t>(filled.joint_count()) + filled.skeleton.end_site_parents.size();
    for (int f = g.first; f <= g.last; ++f)
        for (size_t k : points) {
            const double e = cm * distance(p[static_cast<size_t>(f - lo) * row + k], truth[static_cast<size_t>(f) * row + k]);
            acc.sum += e;
            acc.count += 1.0;
            acc.worst = std::max(acc.worst, e);
        }
    double edge = 0.0;
    for (int f : {g.first, g.last + 1}) {
        if (f < 1 || f >= filled.frame_count) continue;
        for (size_t k : points)
            edge = std::max(edge, distance(p[static_cast<size_t>(f - lo) * row + k], p[static_cast<size_t>(f - 1 - lo) * row + k]));
    }
    const double ratio = p95 > 0.0 ? edge / p95 : 0.0;
    acc.cases += 1;
    acc.cont_sum += ratio;
    acc.cont_worst = std::max(acc.cont_worst, ratio);
}

}  // namespace

double centimetres_per_unit(const Clip& clip) { return clip.length_unit != 1.0 ? 2.54 / clip.length_unit : 1.0; }

FillEvalResult evaluate_fill(const std::vector<Clip>& clips, const std::vector<std::string>& names,
                             const FillEvalOptions& o, const std::vector<Clip>& extra) {
    if (clips.size() < 2) throw ImportError("--clips", 0, "leave-one-out needs at least two clips");
    for (size_t c = 1; c < clips.size(); ++c)
        if (const Outcome same = check_fill_skeleton(clips[0].skeleton, clips[c].skeleton); !same.ok())
            throw ImportError(c < names.size() ? names[c] : clips[c].name, 0, same.problem());
    for (const Clip& e : extra)
        if (const Outcome same = check_fill_skeleton(clips[0].skeleton, e.skeleton); !same.ok())
            throw ImportError(e.name, 0, same.problem());
    const std::vector<bool> hidden = resolve_hidden_joints(clips[0].skeleton, o.hide, "--hide");
    const std::vector<size_t> points = moving_points(clips[0].skeleton, hidden);
    const FillMethod methods[] = {FillMethod::graph, FillMethod::slerp, FillMethod::hold};
    const size_t gaps = o.gaps_s.size();
    std::vector<Accumulator> acc(3 * gaps);
    FillEvalResult result;
    result.cm_per_unit = centimetres_per_unit(clips[0]);
    SplitMix64 rng{o.seed};
    for (size_t c = 0; c < clips.size(); ++c) {
        std::vector<Clip> others;
        for (size_t d = 0; d < clips.size(); ++d)
            if (d != c) others.push_back(clips[d]);
        others.insert(others.end(), extra.begin(), extra.end());
        const FillDatabase db = prepare_fill_database(std::move(others));
        const Clip& clip = clips[c];
        const std::vector<vec3> truth = model_positions_with_end_sites(clip);
        const size_t row = static_cast<size_t>(clip.joint_count()) + clip.skeleton.end_site_parents.size();
        const double p95 = percentile95(frame_moves(truth, row, points, clip.frame_count));
        for (size_t gi = 0; gi < gaps; ++gi) {
            const int length = std::max(1, static_cast<int>(std::lround(o.gaps_s[gi] * clip.frame_rate)));
            if (clip.frame_count - 2 < length) {
                ++result.skipped;
                continue;
            }
            std::vector<Accumulator> mine(3);
            for (int t = 0; t < o.trials; ++t) {
                FillGap g;
                g.hidden = hidden;
                g.first = 1 + static_cast<int>(rng.next() % static_cast<std::uint64_t>(clip.frame_count - 1 - length));
                g.last = g.first + length - 1;
                for (size_t m = 0; m < 3; ++m) {
                    Clip filled = clip;
                    FillOptions fo = o.fill;
                    fo.method = methods[m];
                    (void)fill_gap(filled, g, &db, fo);
                    measure(filled, truth, g, points, p95, result.cm_per_unit, acc[m * gaps + gi]);
                    measure(filled, truth, g, points, p95, result.cm_per_unit, mine[m]);
                }
            }
            for (size_t m = 0; m < 3; ++m)
                result.per_clip.push_back({static_cast<int>(c), methods[m], o.gaps_s[gi], mine[m].cases,
                                           mine[m].count > 0 ? mine[m].sum / mine[m].count : 0.0});
        }
    }
    for (size_t m = 0; m < 3; ++m)
        for (size_t gi = 0; gi < gaps; ++gi) {
            const Accumulator& a = acc[m * gaps + gi];
            FillEvalRow r;
            r.method = methods[m];
            r.gap_s = o.gaps_s[gi];
            r.cases = a.cases;
            r.mean_cm = a.count > 0 ? a.sum / a.count : 0.0;
            r.worst_cm = a.worst;
            r.continuity_mean = a.cases > 0 ? a.cont_sum / a.cases : 0.0;
            r.continuity_worst = a.cont_worst;
            result.rows.push_back(r);
        }
    return result;
}

}  // namespace marionette::offline
