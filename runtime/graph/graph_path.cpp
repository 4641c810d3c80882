#include "runtime/graph/graph_path.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

namespace marionette {

GraphLocation locate_frame(const MotionGraph& g, int clip, int frame) {
    GraphLocation best;
    for (const GraphEdge& e : g.edges) {
        if (e.kind != GraphEdgeKind::clip) continue;
        const GraphNode& a = g.nodes[static_cast<size_t>(e.from)];
        const GraphNode& b = g.nodes[static_cast<size_t>(e.to)];
        if (a.clip == clip && a.frame <= frame && frame < b.frame) return {e.from, frame - a.frame};
        if (b.clip == clip && b.frame == frame) best = {e.to, 0};
    }
    return best;
}

double edge_cost(const MotionGraph& g, const GraphEdge& e, double transition_weight) {
    return transition_weight * e.cost + e.frames / g.frame_rate;
}

GraphPathSearch::GraphPathSearch(const MotionGraph& g, double transition_weight)
    : graph_(g), transition_weight_(transition_weight) {
    const size_t n = g.nodes.size();
    distance_.resize(n);
    via_edge_.resize(n);
    stamp_.assign(n, 0);
    goal_extra_.assign(n, -1.0);
    goal_after_.assign(n, 0);
    heap_.reserve(g.edges.size() + n + 1);
    path_.resize(n);
}

void GraphPathSearch::clear_goals() {
    goal_labels_ = 0;
    if (!frame_goals_) return;
    std::fill(goal_extra_.begin(), goal_extra_.end(), -1.0);
    std::fill(goal_after_.begin(), goal_after_.end(), 0);
    frame_goals_ = false;
}

void GraphPathSearch::add_label_goal(int label) {
    if (label < 0 || label >= kMaxGraphLabels) return;
    goal_labels_ |= 1u << label;
}

bool GraphPathSearch::add_frame_goal(int clip, int frame) {
    const GraphLocation at = locate_frame(graph_, clip, frame);
    if (at.node < 0) return false;
    goal_extra_[static_cast<size_t>(at.node)] = at.frames_after / graph_.frame_rate;
    goal_after_[static_cast<size_t>(at.node)] = at.frames_after;
    frame_goals_ = true;
    return true;
}

double GraphPathSearch::distance(size_t node) const {
    return stamp_[node] == generation_ ? distance_[node] : std::numeric_limits<double>::infinity();
}

// A label goal costs nothing more on arrival; a frame goal adds the frames still
// to play after its node. −1: not a goal.
double GraphPathSearch::goal_extra(size_t node) const {
    const double frame_extra = goal_extra_[node];
    const bool labelled = (graph_.clips[static_cast<size_t>(graph_.nodes[node].clip)].label_mask & goal_labels_) != 0;
    return labelled ? 0.0 : frame_extra;
}

bool GraphPathSearch::run(int start) {
    begin(start);
    return advance(std::numeric_limits<std::int64_t>::max()) == PathSearchStatus::found;
}

void GraphPathSearch::begin(int start) {
    if (++generation_ == 0) {  // wrapped: old stamps could alias the new generation
        std::fill(stamp_.begin(), stamp_.end(), 0u);
        generation_ = 1;
    }
    heap_.clear();
    path_length_ = 0;
    goal_node_ = -1;
    goal_frames_after_ = 0;
    cost_ = 0.0;
    best_ = std::numeric_limits<double>::infinity();
    settled_ = 0;
    pops_ = 0;
    start_ = start;
    if (start < 0 || static_cast<size_t>(start) >= graph_.nodes.size()) {
        status_ = PathSearchStatus::unreachable;
        return;
    }
    const size_t s = static_cast<size_t>(start);
    stamp_[s] = generation_;
    distance_[s] = 0.0;
    via_edge_[s] = -1;
    heap_.push_back({0.0, start});
    status_ = PathSearchStatus::running;
}

PathSearchStatus GraphPathSearch::advance(std::int64_t max_pops) {
    // Min-heap on (cost, node): ties resolve by node index, so results are deterministic.
    const auto later = [](const std::pair<double, std::int32_t>& a, const std::pair<double, std::int32_t>& b) {
        return a.first != b.first ? a.first > b.first : a.second > b.second;
    };
    const std::int64_t limit =
        max_pops >= std::numeric_limits<std::int64_t>::max() - pops_ ? std::numeric_limits<std::int64_t>::max() : pops_ + max_pops;
    // The end is checked before the budget, so where the query stands after k pops
    // does not depend on how the pops were sliced.
    while (status_ == PathSearchStatus::running) {
        if (heap_.empty()) {
            finish();
            break;
        }
        if (pops_ >= limit) break;
        std::pop_heap(heap_.begin(), heap_.end(), later);
        const auto [d, v] = heap_.back();
        heap_.pop_back();
        ++pops_;
        // Every later node costs at least d, so once d reaches the best goal we are done.
        if (d >= best_) {
            finish();
            break;
        }
        if (d > distance(static_cast<size_t>(v))) continue;
        ++settled_;
        const double extra = goal_extra(static_cast<size_t>(v));
        if (extra >= 0.0 && d + extra < best_) {
            best_ = d + extra;
            goal_node_ = v;
        }
        for (const GraphEdge& e : graph_.out_edges(v)) {
            const double nd = d + edge_cost(graph_, e, transition_weight_);
            const size_t w = static_cast<size_t>(e.to);
            // Lazy deletion pushes at most one entry per edge relaxation: the
            // capacity reserved (edges + nodes + 1) is never exceeded.
            if (nd < distance(w) && heap_.size() < heap_.capacity()) {
                stamp_[w] = generation_;
                distance_[w] = nd;
                via_edge_[w] = graph_.edge_index(e);
                heap_.push_back({nd, static_cast<std::int32_t>(w)});
                std::push_heap(heap_.begin(), heap_.end(), later);
            }
        }
    }
    return status_;
}

void GraphPathSearch::finish() {
    heap_.clear();
    if (goal_node_ < 0) {
        status_ = PathSearchStatus::unreachable;
        return;
    }
    status_ = PathSearchStatus::found;
    cost_ = best_;
    goal_frames_after_ = goal_after_[static_cast<size_t>(goal_node_)];
    std::int32_t v = goal_node_;
    size_t count = 0;
    while (v != start_ && count < path_.size()) {
        const std::int32_t e = via_edge_[static_cast<size_t>(v)];
        path_[count++] = e;
        v = graph_.edges[static_cast<size_t>(e)].from;
    }
    std::reverse(path_.begin(), path_.begin() + static_cast<std::ptrdiff_t>(count));
    path_length_ = count;
}

float transition_weight(int p, int k) {
    const double t = static_cast<double>(p + 1) / k;
    return static_cast<float>(2.0 * t * t * t - 3.0 * t * t + 1.0);
}

PlanarTransform edge_alignment(const GraphEdge& e) { return {e.align_angle, e.align_dx, e.align_dz}; }

void graph_frame_pose(const MotionGraph& g, int global_frame, const PlanarTransform& world, std::span<quat> rotations,
                      std::span<vec3> translations) {
    const size_t joints = static_cast<size_t>(g.joint_count());
    const size_t base = static_cast<size_t>(global_frame) * joints;
    const quat yaw = planar_rotation(world);
    for (size_t j = 0; j < joints; ++j) {
        rotations[j] = g.rotations[base + j];
        translations[j] = g.translations[base + j];
        if (g.skeleton.parents[j] == kNoParent) {
            rotations[j] = quat_normalize(quat_mul(yaw, rotations[j]));
            translations[j] = apply_planar(world, translations[j]);
        }
    }
}

namespace {
// Window time `time` (frames from `first`, ≥ 0, ≤ k − 1) of joint j: the two
// neighbouring frames slerped / lerped (one frame when the time is whole).
void window_sample(const MotionGraph& g, int first, float time, size_t j, quat& q, vec3& t) {
    const size_t joints = static_cast<size_t>(g.joint_count());
    const int whole = static_cast<int>(time);
    const float u = time - static_cast<float>(whole);
    const size_t base = static_cast<size_t>(first + whole) * joints + j;
    q = g.rotations[base];
    t = g.translations[base];
    if (u > 0.0f) {
        q = quat_slerp(q, g.rotations[base + joints], u);
        t = lerp(t, g.translations[base + joints], u);
    }
}

// First global frames of a transition's source and target windows.
void transition_windows(const MotionGraph& g, const GraphEdge& e, int& first_a, int& first_b) {
    const GraphNode& a = g.nodes[static_cast<size_t>(e.from)];
    const GraphNode& b = g.nodes[static_cast<size_t>(e.to)];
    first_a = g.clips[static_cast<size_t>(a.clip)].first_frame + a.frame;
    first_b = g.clips[static_cast<size_t>(b.clip)].first_frame + b.frame - g.window_frames;
}

// The DTW of a transition's windows: the k × k accumulated costs (row-major,
// +inf outside the band) and the path from (0, 0) to (k − 1, k − 1).
struct WarpPath {
    std::vector<double> cost, total;
    std::vector<std::pair<int, int>> path;
};
WarpPath warp_path(const MotionGraph& g, const GraphEdge& e) {
    const int k = g.window_frames;
    int first_a = 0, first_b = 0;
    transition_windows(g, e, first_a, first_b);
    const size_t joints = static_cast<size_t>(g.joint_count());
    const int band = std::max(1, static_cast<int>(kWarpBandFraction * k));
    WarpPath w;
    const double inf = std::numeric_limits<double>::infinity();
    w.cost.assign(static_cast<size_t>(k * k), inf);
    w.total.assign(static_cast<size_t>(k * k), inf);
    auto at = [k](int i, int j) { return static_cast<size_t>(i * k + j); };
    for (int i = 0; i < k; ++i)
        for (int j = std::max(0, i - band); j <= std::min(k - 1, i + band); ++j) {
            const size_t ba = static_cast<size_t>(first_a + i) * joints, bb = static_cast<size_t>(first_b + j) * joints;
            double d = 0.0;
            for (size_t q = 0; q < joints; ++q) {
                if (g.skeleton.parents[q] == kNoParent) continue;
                const quat qa = g.rotations[ba + q], qb = g.rotations[bb + q];
                const double dot = static_cast<double>(qa.w) * qb.w + static_cast<double>(qa.x) * qb.x +
                                   static_cast<double>(qa.y) * qb.y + static_cast<double>(qa.z) * qb.z;
                d += 1.0 - std::fabs(dot);
            }
            w.cost[at(i, j)] = d;
            double best = i == 0 && j == 0 ? 0.0 : inf;
            if (i > 0 && j > 0) best = std::min(best, w.total[at(i - 1, j - 1)]);
            if (i > 0) best = std::min(best, w.total[at(i - 1, j)]);
            if (j > 0) best = std::min(best, w.total[at(i, j - 1)]);
            w.total[at(i, j)] = d + best;
        }
    // Back from the end: the diagonal on a tie, then advancing the source.
    int i = k - 1, j = k - 1;
    w.path.push_back({i, j});
    while (i > 0 || j > 0) {
        const double diag = i > 0 && j > 0 ? w.total[at(i - 1, j - 1)] : inf;
        const double up = i > 0 ? w.total[at(i - 1, j)] : inf;
        const double left = j > 0 ? w.total[at(i, j - 1)] : inf;
        if (diag <= up && diag <= left) --i, --j;
        else if (up <= left) --i;
        else --j;
        w.path.push_back({i, j});
    }
    std::reverse(w.path.begin(), w.path.end());
    return w;
}
}  // namespace

void transition_time_warp(const MotionGraph& g, const GraphEdge& e, std::span<float> out) {
    const int k = g.window_frames;
    if (out.size() != static_cast<size_t>(2 * k)) return;
    for (int p = 0; p < k; ++p) out[static_cast<size_t>(p)] = out[static_cast<size_t>(k + p)] = static_cast<float>(p);
    if (e.kind != GraphEdgeKind::transition || k < 3 || k > kMaxWarpWindowFrames || e.frames != k) return;
    const WarpPath w = warp_path(g, e);
    const int last = static_cast<int>(w.path.size()) - 1;
    std::vector<double> a(static_cast<size_t>(k)), b(static_cast<size_t>(k));
    for (int p = 0; p < k; ++p) {
        // Resampled by position along the path (its points evenly spaced).
        const double s = static_cast<double>(p) * last / (k - 1);
        const int idx = std::min(static_cast<int>(s), last - 1 < 0 ? 0 : last - 1);
        const double u = last > 0 ? s - idx : 0.0;
        const auto& p0 = w.path[static_cast<size_t>(idx)];
        const auto& p1 = w.path[static_cast<size_t>(last > 0 ? idx + 1 : idx)];
        a[static_cast<size_t>(p)] = p0.first + (p1.first - p0.first) * u;
        b[static_cast<size_t>(p)] = p0.second + (p1.second - p0.second) * u;
    }
    for (int pass = 0; pass < 2; ++pass)
        for (std::vector<double>* v : {&a, &b}) {
            std::vector<double> smooth = *v;
            for (int p = 1; p + 1 < k; ++p)
                smooth[static_cast<size_t>(p)] = 0.25 * (*v)[static_cast<size_t>(p - 1)] + 0.5 * (*v)[static_cast<size_t>(p)] +
                                                 0.25 * (*v)[static_cast<size_t>(p + 1)];
            *v = smooth;
        }
    for (int p = 0; p < k; ++p) {
        out[static_cast<size_t>(p)] = static_cast<float>(std::min(a[static_cast<size_t>(p)], static_cast<double>(k - 1)));
        out[static_cast<size_t>(k + p)] = static_cast<float>(std::min(b[static_cast<size_t>(p)], static_cast<double>(k - 1)));
    }
}

bool transition_warps_affordable(const MotionGraph& g) {
    const int k = g.window_frames;
    if (k < 3 || k > kMaxWarpWindowFrames) return false;
    const double band = std::max(1, static_cast<int>(kWarpBandFraction * k));
    const double cells = static_cast<double>(k) * (2.0 * band + 1.0) * static_cast<double>(g.joint_count());
    double work = 0.0;
    for (const GraphEdge& e : g.edges)
        if (e.kind == GraphEdgeKind::transition) work += cells;
    return work <= kMaxWarpWork;
}

void transition_warp_costs(const MotionGraph& g, const GraphEdge& e, double& warped, double& diagonal) {
    warped = diagonal = 0.0;
    const int k = g.window_frames;
    if (e.kind != GraphEdgeKind::transition || k < 1 || k > kMaxWarpWindowFrames || e.frames != k) return;
    const WarpPath w = warp_path(g, e);
    warped = w.total.back();
    for (int i = 0; i < k; ++i) diagonal += w.cost[static_cast<size_t>(i * k + i)];
}

std::uint8_t graph_transition_pose(const MotionGraph& g, const GraphEdge& e, int p, const PlanarTransform& world,
                                   std::span<quat> rotations, std::span<vec3> translations, std::span<const float> warp) {
    const int k = g.window_frames;
    int first_a = 0, first_b = 0;
    transition_windows(g, e, first_a, first_b);
    const bool warped = warp.size() == static_cast<size_t>(2 * k);
    const float time_a = warped ? warp[static_cast<size_t>(p)] : static_cast<float>(p);
    const float time_b = warped ? warp[static_cast<size_t>(k + p)] : static_cast<float>(p);
    const int fa = first_a + static_cast<int>(time_a + 0.5f), fb = first_b + static_cast<int>(time_b + 0.5f);
    const PlanarTransform world_b = compose_planar(world, edge_alignment(e));
    const float alpha = transition_weight(p, k);
    const size_t joints = static_cast<size_t>(g.joint_count());
    const quat yaw_a = planar_rotation(world), yaw_b = planar_rotation(world_b);
    for (size_t j = 0; j < joints; ++j) {
        quat qa, qb;
        vec3 ta, tb;
        window_sample(g, first_a, time_a, j, qa, ta);
        window_sample(g, first_b, time_b, j, qb, tb);
        if (g.skeleton.parents[j] == kNoParent) {
            qa = quat_mul(yaw_a, qa);
            qb = quat_mul(yaw_b, qb);
            ta = apply_planar(world, ta);
            tb = apply_planar(world_b, tb);
        }
        rotations[j] = quat_slerp(qa, qb, 1.0f - alpha);
        translations[j] = lerp(ta, tb, 1.0f - alpha);
    }
    return alpha >= 0.5f ? g.contacts[static_cast<size_t>(fa)] : g.contacts[static_cast<size_t>(fb)];
}

Clip synthesize_path(const MotionGraph& g, int start_clip, int start_frame, std::span<const std::int32_t> edges,
                     int frames_after) {
    Clip out;
    out.name = "graph_path";
    out.skeleton = g.skeleton;
    out.animated_translation = g.animated_translation;
    out.length_unit = g.length_unit;
    out.frame_rate = g.frame_rate;
    const size_t joints = static_cast<size_t>(g.joint_count());
    std::vector<quat> r(joints);
    std::vector<vec3> t(joints);
    const auto emit = [&] {
        out.rotations.insert(out.rotations.end(), r.begin(), r.end());
        out.translations.insert(out.translations.end(), t.begin(), t.end());
        ++out.frame_count;
    };
    PlanarTransform world;
    int clip = start_clip, frame = start_frame;
    for (const std::int32_t ei : edges) {
        const GraphEdge& e = g.edges[static_cast<size_t>(ei)];
        const GraphNode& from = g.nodes[static_cast<size_t>(e.from)];
        // Frames of the current clip up to the edge's start (only before the first edge).
        for (; clip == from.clip && frame < from.frame; ++frame) {
            graph_frame_pose(g, g.clips[static_cast<size_t>(clip)].first_frame + frame, world, r, t);
            emit();
        }
        if (e.kind == GraphEdgeKind::clip) {
            for (int f = from.frame; f < from.frame + e.frames; ++f) {
                graph_frame_pose(g, g.clips[static_cast<size_t>(from.clip)].first_frame + f, world, r, t);
                emit();
            }
        } else {
            std::vector<float> warp(2 * static_cast<size_t>(g.window_frames));
            transition_time_warp(g, e, warp);
            for (int p = 0; p < e.frames; ++p) {
                graph_transition_pose(g, e, p, world, r, t, warp);
                emit();
            }
            world = compose_planar(world, edge_alignment(e));
        }
        const GraphNode& to = g.nodes[static_cast<size_t>(e.to)];
        clip = to.clip;
        frame = to.frame;
    }
    const int last = std::min(frame + frames_after, g.clips[static_cast<size_t>(clip)].frame_count - 1);
    for (; frame <= last; ++frame) {
        graph_frame_pose(g, g.clips[static_cast<size_t>(clip)].first_frame + frame, world, r, t);
        emit();
    }
    return out;
}

}  // namespace marionette
