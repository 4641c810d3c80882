#include "graph_builder/fill_search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>

#include "runtime/math/planar_alignment.hpp"

namespace marionette::offline {

namespace {

// Database seconds per clip second tried by the coarse search (1 must be one of
// them: a clip that truly follows the database is found exactly).
constexpr double kScales[] = {0.7, 0.8, 0.9, 1.0, 1.1, 1.25, 1.4};
constexpr int kCoarseFrames = 24;  // query frames the coarse search compares
constexpr int kAhead = 3;          // database frames to the root's look-ahead point (0.1 s)

// The clip around the gap at the database rate: per query frame, the joints that
// count (visible ones inside the gap, all outside) and their model positions.
struct Query {
    double t0 = 0.0;
    int frames = 0;
    std::vector<int> visible, all;
    std::vector<bool> in_gap;
    int root = -1;
    // Per frame: first the root's position kAhead database frames later (so the
    // one alignment of the frame also compares the root's velocity in the body's
    // frame: how fast and which way it moves, which per-frame alignment alone
    // discards), then the frame's joints.
    std::vector<vec3> points;          // per frame, its joints' positions in order
    std::vector<size_t> offset;        // first point of each frame
    const std::vector<int>& joints(int i) const { return in_gap[static_cast<size_t>(i)] ? visible : all; }
};

Query build_query(const Clip& clip, const FillGap& gap, double rate, double window_s) {
    Query q;
    const double r_in = clip.frame_rate;
    const double t_first = gap.first / r_in, t_last = gap.last / r_in;
    q.t0 = std::max(0.0, t_first - window_s);
    const double t1 = std::min(clip.duration(), t_last + window_s);
    q.frames = static_cast<int>(std::floor((t1 - q.t0) * rate + 1e-9)) + 1;
    const int n = clip.joint_count();
    for (int j = 0; j < n; ++j) {
        if (clip.skeleton.parents[static_cast<size_t>(j)] == kNoParent && q.root < 0) q.root = j;
        q.all.push_back(j);
        if (!gap.hidden[static_cast<size_t>(j)]) q.visible.push_back(j);
    }
    std::vector<quat> lr(static_cast<size_t>(n)), mr(static_cast<size_t>(n));
    std::vector<vec3> lt(static_cast<size_t>(n)), mp(static_cast<size_t>(n));
    for (int i = 0; i < q.frames; ++i) {
        const double t = q.t0 + i / rate;
        // Inside the gap (with a half-frame margin at the clip's rate) only visible joints count.
        q.in_gap.push_back(t > t_first - 0.5 / r_in && t < t_last + 0.5 / r_in);
        const LocalToModelJob fk{clip.skeleton.parents, {lr, lt}, {mr, mp}};
        sample_clip(clip, t + kAhead / rate, ClipWrap::clamp, lr, lt);
        (void)fk.run();
        q.offset.push_back(q.points.size());
        q.points.push_back(mp[static_cast<size_t>(q.root)]);
        sample_clip(clip, t, ClipWrap::clamp, lr, lt);
        (void)fk.run();
        for (int j : q.joints(i)) q.points.push_back(mp[static_cast<size_t>(j)]);
    }
    q.offset.push_back(q.points.size());
    return q;
}

// The look-ahead point's weight first, then 1 per joint.
std::vector<float> point_weights(const Query& q, double velocity_weight) {
    std::vector<float> w(q.all.size() + 1, 1.0f);
    w[0] = static_cast<float>(velocity_weight);
    return w;
}

struct Candidate {
    double distance = 0.0;
    int clip = -1;
    double start = 0.0;  // database frame of query frame 0
    double scale = 1.0;
};

vec3 db_point(const FillDatabase& db, int c, int joints, double frame, int j) {
    const std::vector<vec3>& p = db.positions[static_cast<size_t>(c)];
    const int f0 = static_cast<int>(frame);
    const int last = db.clips[static_cast<size_t>(c)].frame_count - 1;
    const int f1 = std::min(f0 + 1, last);
    const float u = static_cast<float>(frame - f0);
    const vec3 a = p[static_cast<size_t>(f0) * static_cast<size_t>(joints) + static_cast<size_t>(j)];
    if (u == 0.0f) return a;
    return lerp(a, p[static_cast<size_t>(f1) * static_cast<size_t>(joints) + static_cast<size_t>(j)], u);
}

// Kovar's distance per frame (a window of one frame): the query frame's points
// against the database frame's, after the rotation about +Y and the ground
// translation that fit them best. Aligning each frame on its own keeps the root's
// path over a long gap (a veer, a turn) from outweighing the pose; the sequence
// of poses still carries the phase and the speed of the motion.
double frame_distance(const Query& q, int i, const FillDatabase& db, int c, double frame, std::vector<vec3>& b,
                      const std::vector<float>& w) {
    const int joints = db.skeleton.joint_count();
    b.clear();
    const double last = db.clips[static_cast<size_t>(c)].frame_count - 1;
    b.push_back(db_point(db, c, joints, std::min(frame + kAhead, last), q.root));
    for (int j : q.joints(i)) b.push_back(db_point(db, c, joints, frame, j));
    const size_t k = q.offset[static_cast<size_t>(i)];
    const std::span<const vec3> a(q.points.data() + k, b.size());
    const std::span<const float> ws(w.data(), b.size());
    return planar_cloud_distance(a, b, ws, align_point_clouds(a, b, ws)) / static_cast<double>(b.size());
}

Candidate score(const Query& q, const std::vector<int>& sample, const FillDatabase& db, int c, double start,
                double scale, std::vector<vec3>& b, const std::vector<float>& w) {
    double sum = 0.0;
    for (int i : sample) sum += frame_distance(q, i, db, c, start + i * scale, b, w);
    return Candidate{sum / static_cast<double>(sample.size()), c, start, scale};
}

std::vector<Candidate> coarse_search(const Query& q, const FillDatabase& db, double velocity_weight, int stride_frames) {
    std::vector<int> sample;
    const int stride = std::max(1, (q.frames + kCoarseFrames - 1) / kCoarseFrames);
    for (int i = 0; i < q.frames; i += stride) sample.push_back(i);
    if (sample.back() != q.frames - 1) sample.push_back(q.frames - 1);
    const std::vector<float> w = point_weights(q, velocity_weight);
    // Clips are scored on every core (worker k takes clips k, k + workers, …);
    // each candidate's score does not depend on which worker made it, and the
    // sort below orders them totally, so the result is the same on any machine.
    const int clips = static_cast<int>(db.clips.size());
    const int workers = std::max(1, std::min(clips, static_cast<int>(std::min(8u, std::thread::hardware_concurrency()))));
    std::vector<std::vector<Candidate>> found(static_cast<size_t>(workers));
    const auto work = [&](int k) {
        std::vector<vec3> b;
        for (int c = k; c < clips; c += workers) {
            const int last = db.clips[static_cast<size_t>(c)].frame_count - 1;
            for (double scale : kScales) {
                const double span = (q.frames - 1) * scale;
                for (int s = 0; s + span <= last + 1e-9; s += stride_frames)
                    found[static_cast<size_t>(k)].push_back(score(q, sample, db, c, s, scale, b, w));
            }
        }
    };
    std::vector<std::thread> threads;  // the calling thread is worker 0
    for (int k = 1; k < workers; ++k) threads.emplace_back(work, k);
    work(0);
    for (std::thread& t : threads) t.join();
    std::vector<Candidate> all;
    for (const std::vector<Candidate>& f : found) all.insert(all.end(), f.begin(), f.end());
    std::sort(all.begin(), all.end(), [](const Candidate& x, const Candidate& y) {
        if (x.distance != y.distance) return x.distance < y.distance;
        if (x.clip != y.clip) return x.clip < y.clip;
        if (x.start != y.start) return x.start < y.start;
        return x.scale < y.scale;
    });
    return all;
}

// The best `count` candidates, no two starting within a quarter span in one clip.
std::vector<Candidate> distinct_best(const std::vector<Candidate>& sorted, int count, int query_frames) {
    std::vector<Candidate> kept;
    for (const Candidate& c : sorted) {
        if (static_cast<int>(kept.size()) >= count) break;
        bool near = false;
        for (const Candidate& k : kept)
            near = near || (k.clip == c.clip && std::abs(k.start - c.start) < 0.25 * query_frames * k.scale);
        if (!near) kept.push_back(c);
    }
    return kept;
}

// Dynamic time warping of the query frames against database frames first..last
// (fixed ends, steps (1,1), (1,0), (0,1), a band around the diagonal), with the
// per-frame distance. Fills `db_frame` (per query frame, the mean matched
// database frame) and returns the mean cost per point along the path.
double dtw_refine(const Query& q, const FillDatabase& db, const Candidate& cand, double velocity_weight,
                  std::vector<double>& db_frame) {
    std::vector<vec3> b;
    const std::vector<float> w = point_weights(q, velocity_weight);
    const int first = static_cast<int>(std::floor(cand.start));
    const int last = std::min(db.clips[static_cast<size_t>(cand.clip)].frame_count - 1,
                              static_cast<int>(std::ceil(cand.start + (q.frames - 1) * cand.scale)));
    const int nq = q.frames, nd = last - first + 1;
    const double slope = nq > 1 ? static_cast<double>(nd - 1) / (nq - 1) : 0.0;
    const int band = std::max(3, static_cast<int>(0.15 * nd));
    const double inf = std::numeric_limits<double>::infinity();
    std::vector<double> cost(static_cast<size_t>(nq) * static_cast<size_t>(nd), inf), acc(cost.size(), inf);
    const auto at = [nd](int i, int j) { return static_cast<size_t>(i) * static_cast<size_t>(nd) + static_cast<size_t>(j); };
    for (int i = 0; i < nq; ++i) {
        const int centre = static_cast<int>(std::lround(i * slope));
        for (int j = std::max(0, centre - band); j <= std::min(nd - 1, centre + band); ++j) {
            cost[at(i, j)] = frame_distance(q, i, db, cand.clip, first + j, b, w);
        }
    }
    for (int i = 0; i < nq; ++i)
        for (int j = 0; j < nd; ++j) {
            if (cost[at(i, j)] == inf) continue;
            double best = (i == 0 && j == 0) ? 0.0 : inf;
            if (i > 0 && j > 0) best = std::min(best, acc[at(i - 1, j - 1)]);
            if (i > 0) best = std::min(best, acc[at(i - 1, j)]);
            if (j > 0) best = std::min(best, acc[at(i, j - 1)]);
            acc[at(i, j)] = best + cost[at(i, j)];
        }
    if (acc[at(nq - 1, nd - 1)] == inf) return inf;
    // Backtrack from the end; per query frame, the mean of its matched database frames.
    std::vector<double> sum(static_cast<size_t>(nq), 0.0), count(static_cast<size_t>(nq), 0.0);
    int i = nq - 1, j = nd - 1, steps = 0;
    for (;;) {
        sum[static_cast<size_t>(i)] += j;
        count[static_cast<size_t>(i)] += 1.0;
        ++steps;
        if (i == 0 && j == 0) break;
        double d = inf, v = inf, h = inf;
        if (i > 0 && j > 0) d = acc[at(i - 1, j - 1)];
        if (i > 0) v = acc[at(i - 1, j)];
        if (j > 0) h = acc[at(i, j - 1)];
        if (d <= v && d <= h) { --i; --j; }
        else if (v <= h) --i;
        else --j;
    }
    db_frame.assign(static_cast<size_t>(nq), 0.0);
    for (int f = 0; f < nq; ++f) db_frame[static_cast<size_t>(f)] = first + sum[static_cast<size_t>(f)] / count[static_cast<size_t>(f)];
    return acc[at(nq - 1, nd - 1)] / steps;
}

// Monotone, then a [1 2 1]/4 smoothing (ends kept): a frozen or skipped frame of
// the warping path would otherwise show as a stall or a jump in the filled joints.
void smooth_mapping(std::vector<double>& f) {
    for (size_t i = 1; i < f.size(); ++i) f[i] = std::max(f[i], f[i - 1]);
    for (int pass = 0; pass < 2; ++pass) {
        std::vector<double> g = f;
        for (size_t i = 1; i + 1 < f.size(); ++i) g[i] = 0.25 * f[i - 1] + 0.5 * f[i] + 0.25 * f[i + 1];
        f = g;
    }
}

}  // namespace

double mapped_db_time(const FillMapping& m, double t) {
    const int n = static_cast<int>(m.db_time.size());
    if (n == 0) return 0.0;
    double u = (t - m.query_t0) * m.query_rate;
    if (!(u > 0.0)) return m.db_time.front();
    if (u >= n - 1) return m.db_time.back();
    const int i = static_cast<int>(u);
    const double f = u - i;
    return m.db_time[static_cast<size_t>(i)] * (1.0 - f) + m.db_time[static_cast<size_t>(i) + 1] * f;
}

std::vector<FillMapping> search_fill_motion(const Clip& clip, const FillGap& gap, const FillDatabase& db,
                                            const FillOptions& o) {
    std::vector<FillMapping> out;
    const Query q = build_query(clip, gap, db.rate, o.window_s);
    if (q.frames < 2 || q.visible.empty()) return out;
    const int refine = std::max({1, o.refine_candidates, o.blend_matches});
    for (const Candidate& c : distinct_best(coarse_search(q, db, o.velocity_weight, std::max(1, o.coarse_stride)), refine, q.frames)) {
        FillMapping m;
        m.query_t0 = q.t0;
        m.query_rate = db.rate;
        const double d = dtw_refine(q, db, c, o.velocity_weight, m.db_time);
        if (!(d < std::numeric_limits<double>::infinity())) continue;
        m.match = {true, c.clip, c.start / db.rate, c.scale, d, 1.0};
        smooth_mapping(m.db_time);
        for (double& t : m.db_time) t /= db.rate;
        out.push_back(std::move(m));
    }
    std::stable_sort(out.begin(), out.end(), [](const FillMapping& a, const FillMapping& b) {
        return a.match.distance < b.match.distance;
    });
    if (static_cast<int>(out.size()) > std::max(1, o.blend_matches)) out.resize(static_cast<size_t>(std::max(1, o.blend_matches)));
    return out;
}

}  // namespace marionette::offline
