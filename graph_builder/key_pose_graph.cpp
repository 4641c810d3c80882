#include "graph_builder/key_pose_graph.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <stdexcept>

#include "graph_builder/graph_builder.hpp"
#include "graph_builder/transition_search.hpp"

namespace marionette::offline {

namespace {

// Model-space joint positions of a pose whose roots are placed by `world`.
std::vector<vec3> placed_positions(const KeyPoseGraph& g, const KeyPose& pose, const PlanarTransform& world) {
    const size_t J = static_cast<size_t>(g.skeleton.joint_count());
    std::vector<quat> rotations = pose.rotations, model_rotations(J);
    std::vector<vec3> translations = pose.translations, positions(J);
    for (size_t j = 0; j < J; ++j)
        if (g.skeleton.parents[j] == kNoParent) {
            rotations[j] = quat_normalize(quat_mul(planar_rotation(world), rotations[j]));
            translations[j] = apply_planar(world, translations[j]);
        }
    const LocalToModelJob fk{g.skeleton.parents, {rotations, translations}, {model_rotations, positions}};
    if (!fk.run()) throw std::invalid_argument("key-pose graph skeleton is not in topological order");
    return positions;
}

double percentile_of(std::vector<double> values, double percentile) {
    if (values.empty()) return 0.0;
    std::sort(values.begin(), values.end());
    const double rank = std::clamp(percentile, 0.0, 100.0) / 100.0 * static_cast<double>(values.size() - 1);
    return values[static_cast<size_t>(rank)];
}

struct Minimum {
    double speed = 0.0;
    std::int32_t frame = 0;  // global
    std::int32_t clip = 0;
};

// Whole-body joint speed per frame (central difference of the aligned poses, RMS
// over the weighted joints, leg lengths per second) and its strict local minima.
std::vector<Minimum> speed_minima(const ClipDatabase& db, std::span<const vec3> positions, double leg, int h) {
    std::vector<Minimum> minima;
    std::int32_t first = 0;
    for (size_t c = 0; c < db.clips.size(); ++c) {
        const int n = db.clips[c].frame_count;
        std::vector<double> speed(static_cast<size_t>(std::max(n, 0)), std::numeric_limits<double>::infinity());
        for (int f = 1; f + 1 < n; ++f)
            speed[static_cast<size_t>(f)] =
                std::sqrt(reference_pair_distance(db, positions, 1, leg, first + f - 1, first + f + 1)) *
                db.analysis_rate_hz / 2.0;
        for (int f = 1; f + 1 < n; ++f) {
            bool is_minimum = true;
            for (int o = -h; o <= h && is_minimum; ++o) {
                const int q = f + o;
                if (o == 0 || q < 1 || q + 1 >= n) continue;
                const double s = speed[static_cast<size_t>(q)], here = speed[static_cast<size_t>(f)];
                is_minimum = o < 0 ? here < s : here <= s;  // a plateau gives its first frame
            }
            if (is_minimum) minima.push_back({speed[static_cast<size_t>(f)], first + f, static_cast<std::int32_t>(c)});
        }
        first += n;
    }
    return minima;
}

// The interpolation step: median over the database of the largest joint move
// between consecutive frames, the root aligned (skeleton units).
double median_aligned_move(const ClipDatabase& db, std::span<const vec3> positions) {
    const size_t J = static_cast<size_t>(db.skeleton.joint_count());
    std::vector<double> moves;
    std::int32_t first = 0;
    for (const Clip& clip : db.clips) {
        for (int f = 1; f < clip.frame_count; ++f) {
            const std::int32_t a = first + f - 1, b = first + f;
            const PlanarTransform t = reference_pair_alignment(db, positions, 1, a, b);
            double largest = 0.0;
            for (size_t j = 0; j < J; ++j)
                largest = std::max(largest, static_cast<double>(glm::length(
                                                positions[static_cast<size_t>(a) * J + j] -
                                                apply_planar(t, positions[static_cast<size_t>(b) * J + j]))));
            moves.push_back(largest);
        }
        first += clip.frame_count;
    }
    const double m = percentile_of(std::move(moves), 50.0);
    return m > 0.0 ? m : 1.0;
}

}  // namespace

Outcome validate_key_pose_graph(const KeyPoseGraph& g) {
    if (Outcome o = validate_skeleton(g.skeleton); !o.ok()) return o;
    const size_t J = static_cast<size_t>(g.skeleton.joint_count());
    if (J == 0) return Outcome::failure("the skeleton has no joints");
    if (g.animated_translation.size() != J || g.joint_weights.size() != J)
        return Outcome::failure("per-joint flags and weights do not match the joint count");
    if (!(g.frame_rate > 0.0) || !(g.leg_length > 0.0) || !(g.step > 0.0) || !std::isfinite(g.frame_rate) ||
        !std::isfinite(g.leg_length) || !std::isfinite(g.step))
        return Outcome::failure("frame_rate, leg_length and step must be positive numbers");
    if (!(g.link_threshold >= 0.0) || !(g.thin_threshold >= 0.0))
        return Outcome::failure("thresholds must be numbers >= 0");
    double weight = 0.0;
    for (size_t j = 0; j < J; ++j) {
        const vec3 o = g.skeleton.rest_offsets[j];
        if (!(g.joint_weights[j] >= 0.0f) || !std::isfinite(g.joint_weights[j]) || !std::isfinite(o.x + o.y + o.z))
            return Outcome::failure("joint " + std::to_string(j) + ": weight must be a finite number >= 0 and the offset finite");
        weight += g.joint_weights[j];
    }
    if (!(weight > 0.0)) return Outcome::failure("the joint weights add up to 0: no pose difference could be measured");
    for (size_t p = 0; p < g.poses.size(); ++p) {
        const KeyPose& k = g.poses[p];
        if (k.rotations.size() != J || k.translations.size() != J)
            return Outcome::failure("pose " + std::to_string(p) + " does not have one rotation and one translation per joint (" +
                                    std::to_string(J) + ")");
        for (size_t j = 0; j < J; ++j) {
            const quat q = k.rotations[j];
            const vec3 t = k.translations[j];
            const double norm = static_cast<double>(quat_dot(q, q));
            if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-3 || !std::isfinite(t.x + t.y + t.z))
                return Outcome::failure("pose " + std::to_string(p) + ", joint " + std::to_string(j) +
                                        ": the rotation must be a unit quaternion and the translation finite");
        }
    }
    const std::int32_t n = static_cast<std::int32_t>(g.poses.size());
    for (size_t e = 0; e < g.edges.size(); ++e) {
        const KeyPoseEdge& k = g.edges[e];
        if (k.from < 0 || k.to < 0 || k.from >= n || k.to >= n)
            return Outcome::failure("edge " + std::to_string(e) + " names a pose id outside 0.." + std::to_string(n - 1));
        if (k.from >= k.to) return Outcome::failure("edge " + std::to_string(e) + ": from must be below to (undirected, listed once)");
        if (!(k.cost >= 0.0) || !std::isfinite(k.cost))
            return Outcome::failure("edge " + std::to_string(e) + ": cost must be a finite number >= 0");
        if (e > 0 && !(std::pair(g.edges[e - 1].from, g.edges[e - 1].to) < std::pair(k.from, k.to)))
            return Outcome::failure("edge " + std::to_string(e) + ": edges must be sorted by (from, to) without repeats");
    }
    return Outcome::success();
}

namespace {

// The pose difference of two posed point clouds (b aligned onto a), leg lengths².
double cloud_difference(const KeyPoseGraph& g, const std::vector<vec3>& pa, const std::vector<vec3>& pb,
                        PlanarTransform* align) {
    const PlanarTransform t = align_point_clouds(pa, pb, g.joint_weights);
    if (align) *align = t;
    double weight = 0.0;
    for (float w : g.joint_weights) weight += w;
    return planar_cloud_distance(pa, pb, g.joint_weights, t) / (weight * g.leg_length * g.leg_length);
}

}  // namespace

double key_pose_difference(const KeyPoseGraph& g, int a, int b, PlanarTransform* align) {
    return cloud_difference(g, placed_positions(g, g.poses[static_cast<size_t>(a)], {}),
                            placed_positions(g, g.poses[static_cast<size_t>(b)], {}), align);
}

void link_key_poses(KeyPoseGraph& g) {
    g.edges.clear();
    const std::int32_t n = static_cast<std::int32_t>(g.poses.size());
    for (std::int32_t a = 0; a < n; ++a)
        for (std::int32_t b = a + 1; b < n; ++b) {
            const double d = key_pose_difference(g, a, b);
            if (d < g.link_threshold) g.edges.push_back({a, b, d});
        }
}

KeyPoseGraph build_key_pose_graph(const ClipDatabase& db, const KeyPoseParams& params, KeyPoseBuildReport* report) {
    KeyPoseGraph g;
    g.skeleton = db.skeleton;
    g.animated_translation = db.animated_translation;
    g.joint_weights = db.joint_weights;
    g.frame_rate = db.analysis_rate_hz;
    g.length_unit = db.length_unit;
    g.leg_length = skeleton_leg_length(db.skeleton, db.left_foot >= 0 ? db.left_foot : db.right_foot);
    const std::vector<vec3> positions = database_positions(db);
    g.step = median_aligned_move(db, positions);
    std::vector<Minimum> minima = speed_minima(db, positions, g.leg_length, std::max(params.minimum_neighbourhood, 1));
    std::sort(minima.begin(), minima.end(),
              [](const Minimum& a, const Minimum& b) { return a.speed != b.speed ? a.speed < b.speed : a.frame < b.frame; });
    // Every minimum as a key pose, and the differences of all pairs (the earlier
    // frame first, as between the graph's ids), with the graph's own difference, so
    // the thinning guarantee holds exactly for the poses kept.
    std::vector<std::int32_t> clip_first(db.clips.size(), 0);
    for (size_t c = 1; c < db.clips.size(); ++c) clip_first[c] = clip_first[c - 1] + db.clips[c - 1].frame_count;
    const size_t m = minima.size();
    std::vector<KeyPose> candidates;
    std::vector<std::vector<vec3>> posed;
    for (const Minimum& mk : minima) {
        const Clip& clip = db.clips[static_cast<size_t>(mk.clip)];
        const int f = mk.frame - clip_first[static_cast<size_t>(mk.clip)];
        const size_t J = static_cast<size_t>(clip.joint_count());
        candidates.push_back({clip.name, f, mk.speed, {clip.frame_rotations(f), clip.frame_rotations(f) + J},
                              {clip.frame_translations(f), clip.frame_translations(f) + J}});
        posed.push_back(placed_positions(g, candidates.back(), {}));
    }
    std::vector<double> d(m * m, 0.0), all;
    for (size_t a = 0; a < m; ++a)
        for (size_t b = a + 1; b < m; ++b) {
            const bool a_first = minima[a].frame < minima[b].frame;
            d[a * m + b] = d[b * m + a] = cloud_difference(g, posed[a_first ? a : b], posed[a_first ? b : a], nullptr);
            all.push_back(d[a * m + b]);
        }
    if (m < 2 && (params.thin_threshold <= 0.0 || params.link_threshold <= 0.0))
        throw std::invalid_argument(std::to_string(m) + " speed minima in " + std::to_string(db.frame_count()) +
                                    " frames: too few to set the thresholds from percentiles (give --thin and --link, "
                                    "or longer clips)");
    g.thin_threshold = params.thin_threshold > 0.0 ? params.thin_threshold : percentile_of(all, params.thin_percentile);
    g.link_threshold = params.link_threshold > 0.0 ? params.link_threshold : percentile_of(all, params.link_percentile);
    if (g.link_threshold <= g.thin_threshold)
        throw std::invalid_argument("the link threshold (" + std::to_string(g.link_threshold) +
                                    ") must be above the thinning threshold (" + std::to_string(g.thin_threshold) +
                                    "): no two key poses are closer than the latter, so no edge would be left");
    // Thinning: slowest first; a minimum closer than the threshold to one kept is dropped.
    std::vector<size_t> kept;
    for (size_t a = 0; a < m; ++a) {
        bool far = true;
        for (size_t k : kept) far = far && d[a * m + k] >= g.thin_threshold;
        if (far) kept.push_back(a);
    }
    std::sort(kept.begin(), kept.end(), [&](size_t a, size_t b) { return minima[a].frame < minima[b].frame; });
    for (size_t k : kept) g.poses.push_back(std::move(candidates[k]));
    link_key_poses(g);
    if (report) {
        report->frames = db.frame_count();
        report->minima = static_cast<std::int64_t>(m);
        const std::vector<std::int32_t> comp = key_pose_components(g);
        std::vector<std::int64_t> sizes(comp.size(), 0);
        for (std::int32_t c : comp) ++sizes[static_cast<size_t>(c)];
        report->components = std::count_if(sizes.begin(), sizes.end(), [](std::int64_t s) { return s > 0; });
        report->largest_component = sizes.empty() ? 0 : *std::max_element(sizes.begin(), sizes.end());
    }
    return g;
}

std::vector<std::int32_t> key_pose_components(const KeyPoseGraph& g) {
    std::vector<std::int32_t> parent(g.poses.size());
    for (size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<std::int32_t>(i);
    const std::function<std::int32_t(std::int32_t)> root = [&](std::int32_t x) {
        while (parent[static_cast<size_t>(x)] != x) x = parent[static_cast<size_t>(x)] = parent[static_cast<size_t>(parent[static_cast<size_t>(x)])];
        return x;
    };
    for (const KeyPoseEdge& e : g.edges) {
        const std::int32_t a = root(e.from), b = root(e.to);
        if (a != b) parent[static_cast<size_t>(std::max(a, b))] = std::min(a, b);  // the smaller id stays the root
    }
    std::vector<std::int32_t> out(parent.size());
    for (size_t i = 0; i < out.size(); ++i) out[i] = root(static_cast<std::int32_t>(i));
    return out;
}

std::vector<std::int32_t> key_pose_path(const KeyPoseGraph& g, int from, int to, double* cost) {
    const size_t n = g.poses.size();
    std::vector<std::vector<std::pair<std::int32_t, double>>> adjacent(n);
    for (const KeyPoseEdge& e : g.edges) {
        adjacent[static_cast<size_t>(e.from)].push_back({e.to, e.cost});
        adjacent[static_cast<size_t>(e.to)].push_back({e.from, e.cost});
    }
    std::vector<double> best(n, std::numeric_limits<double>::infinity());
    std::vector<std::int32_t> previous(n, -1);
    std::vector<bool> settled(n, false);
    using Entry = std::pair<double, std::int32_t>;  // (cost, pose): equal costs pop the smaller id first
    std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> heap;
    best[static_cast<size_t>(from)] = 0.0;
    heap.push({0.0, from});
    while (!heap.empty()) {
        const auto [c, p] = heap.top();
        heap.pop();
        if (settled[static_cast<size_t>(p)]) continue;
        settled[static_cast<size_t>(p)] = true;
        if (p == to) break;
        for (const auto& [q, w] : adjacent[static_cast<size_t>(p)]) {
            const double nc = c + w;
            // Strictly cheaper, or as cheap through a smaller predecessor: one answer.
            if (nc < best[static_cast<size_t>(q)] ||
                (nc == best[static_cast<size_t>(q)] && !settled[static_cast<size_t>(q)] && p < previous[static_cast<size_t>(q)])) {
                best[static_cast<size_t>(q)] = nc;
                previous[static_cast<size_t>(q)] = p;
                heap.push({nc, q});
            }
        }
    }
    if (!settled[static_cast<size_t>(to)]) return {};
    if (cost) *cost = best[static_cast<size_t>(to)];
    std::vector<std::int32_t> path;
    for (std::int32_t p = to; p >= 0; p = p == from ? -1 : previous[static_cast<size_t>(p)]) path.push_back(p);
    std::reverse(path.begin(), path.end());
    return path;
}

namespace {

// frames + 1 poses from a (placed by wa) to b (placed by wb), smoothstep timed:
// rotations slerped, translations lerped, appended to the flat arrays.
void blend_poses(const KeyPoseGraph& g, const KeyPose& a, const PlanarTransform& wa, const KeyPose& b,
                 const PlanarTransform& wb, int frames, std::vector<quat>& rotations, std::vector<vec3>& translations) {
    const size_t J = static_cast<size_t>(g.skeleton.joint_count());
    for (int i = 0; i <= frames; ++i) {
        const double s = static_cast<double>(i) / frames;
        const float u = static_cast<float>(s * s * (3.0 - 2.0 * s));  // smoothstep
        for (size_t j = 0; j < J; ++j) {
            quat ra = a.rotations[j], rb = b.rotations[j];
            vec3 ta = a.translations[j], tb = b.translations[j];
            if (g.skeleton.parents[j] == kNoParent) {
                ra = quat_normalize(quat_mul(planar_rotation(wa), ra));
                rb = quat_normalize(quat_mul(planar_rotation(wb), rb));
                ta = apply_planar(wa, ta);
                tb = apply_planar(wb, tb);
            }
            rotations.push_back(i == frames ? rb : quat_slerp(ra, rb, u));
            translations.push_back(i == frames ? tb : lerp(ta, tb, u));
        }
    }
}

// Largest per-frame joint move over `count` consecutive poses (model space).
double largest_move(const Skeleton& skeleton, const std::vector<quat>& rotations, const std::vector<vec3>& translations,
                    int count) {
    const size_t J = static_cast<size_t>(skeleton.joint_count());
    std::vector<quat> model_rotations(J);
    std::vector<vec3> previous(J), current(J);
    double largest = 0.0;
    for (int f = 0; f < count; ++f) {
        const LocalToModelJob fk{skeleton.parents,
                                 {std::span<const quat>(rotations.data() + static_cast<size_t>(f) * J, J),
                                  std::span<const vec3>(translations.data() + static_cast<size_t>(f) * J, J)},
                                 {model_rotations, current}};
        if (!fk.run()) throw std::invalid_argument("skeleton is not in topological order");
        if (f > 0)
            for (size_t j = 0; j < J; ++j) largest = std::max(largest, static_cast<double>(glm::length(current[j] - previous[j])));
        std::swap(previous, current);
    }
    return largest;
}

// One hop: sized from the largest joint displacement (chord / step frames, so the
// smoothstep peak is 1.5 step), then lengthened while joints swinging along arcs
// still move more than 1.5 step in a frame.
void append_hop(Clip& out, const KeyPoseGraph& g, const KeyPose& a, const PlanarTransform& wa, const KeyPose& b,
                const PlanarTransform& wb) {
    const std::vector<vec3> pa = placed_positions(g, a, wa), pb = placed_positions(g, b, wb);
    double chord = 0.0;
    for (size_t j = 0; j < pa.size(); ++j) chord = std::max(chord, static_cast<double>(glm::length(pa[j] - pb[j])));
    const double limit = 1.5 * g.step;
    int frames = std::max(1, static_cast<int>(std::ceil(chord / g.step)));
    std::vector<quat> rotations;
    std::vector<vec3> translations;
    for (int attempt = 0; attempt < 8; ++attempt) {
        rotations.clear();
        translations.clear();
        blend_poses(g, a, wa, b, wb, frames, rotations, translations);
        const double move = largest_move(g.skeleton, rotations, translations, frames + 1);
        if (move <= limit) break;
        frames = std::max(frames + 1, static_cast<int>(std::ceil(frames * move / limit)));
    }
    const size_t keep = static_cast<size_t>(frames) * static_cast<size_t>(g.skeleton.joint_count());  // b starts the next hop
    out.rotations.insert(out.rotations.end(), rotations.begin(), rotations.begin() + static_cast<std::ptrdiff_t>(keep));
    out.translations.insert(out.translations.end(), translations.begin(), translations.begin() + static_cast<std::ptrdiff_t>(keep));
    out.frame_count += frames;
}

}  // namespace

Clip synthesize_key_pose_path(const KeyPoseGraph& g, const std::vector<std::int32_t>& path) {
    Clip out;
    out.name = "key_pose_path";
    out.skeleton = g.skeleton;
    out.frame_rate = g.frame_rate;
    out.animated_translation = g.animated_translation;
    out.length_unit = g.length_unit;
    if (path.empty()) return out;
    PlanarTransform world;  // the first pose stays where its clip had it
    for (size_t s = 0; s + 1 < path.size(); ++s) {
        const KeyPose& a = g.poses[static_cast<size_t>(path[s])];
        const KeyPose& b = g.poses[static_cast<size_t>(path[s + 1])];
        const std::vector<vec3> pa = placed_positions(g, a, {});
        const std::vector<vec3> pb = placed_positions(g, b, {});
        const PlanarTransform next = compose_planar(world, align_point_clouds(pa, pb, g.joint_weights));
        append_hop(out, g, a, world, b, next);
        world = next;
    }
    // The last key pose itself closes the animation.
    std::vector<quat> rotations;
    std::vector<vec3> translations;
    const KeyPose& last = g.poses[static_cast<size_t>(path.back())];
    blend_poses(g, last, world, last, world, 1, rotations, translations);
    const size_t J = static_cast<size_t>(g.skeleton.joint_count());
    out.rotations.insert(out.rotations.end(), rotations.begin() + static_cast<std::ptrdiff_t>(J), rotations.end());
    out.translations.insert(out.translations.end(), translations.begin() + static_cast<std::ptrdiff_t>(J), translations.end());
    ++out.frame_count;
    return out;
}

PopStats clip_pop_stats(const Clip& clip) {
    const size_t J = static_cast<size_t>(clip.joint_count());
    std::vector<quat> model_rotations(J);
    std::vector<vec3> previous(J), current(J);
    std::vector<double> moves;
    for (int f = 0; f < clip.frame_count; ++f) {
        const LocalToModelJob fk{clip.skeleton.parents,
                                 {std::span<const quat>(clip.frame_rotations(f), J), std::span<const vec3>(clip.frame_translations(f), J)},
                                 {model_rotations, current}};
        if (!fk.run()) throw std::invalid_argument("clip skeleton is not in topological order");
        if (f > 0) {
            double largest = 0.0;
            for (size_t j = 0; j < J; ++j) largest = std::max(largest, static_cast<double>(glm::length(current[j] - previous[j])));
            moves.push_back(largest);
        }
        std::swap(previous, current);
    }
    PopStats s;
    if (moves.empty()) return s;
    s.largest = *std::max_element(moves.begin(), moves.end());
    s.p95 = percentile_of(moves, 95.0);
    return s;
}

}  // namespace marionette::offline
