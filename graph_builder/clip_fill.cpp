#include "graph_builder/clip_fill.hpp"

#include <xxhash.h>

#include <algorithm>
#include <cstdlib>

#include "graph_builder/fill_search.hpp"
#include "runtime/errors/import_error.hpp"

namespace marionette::offline {

namespace {

std::string lower_bare(const std::string& name) {
    std::string s = name.substr(name.rfind(':') == std::string::npos ? 0 : name.rfind(':') + 1);
    for (char& c : s) c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
    return s;
}

const std::vector<std::string>& group_names(const std::string& group) {
    static const std::vector<std::string> none;
    static const std::vector<std::pair<std::string, std::vector<std::string>>> table = {
        {"left_leg", {"lfemur", "leftupleg", "leftupperleg", "lefthip", "leftthigh", "l_hip", "lthigh"}},
        {"right_leg", {"rfemur", "rightupleg", "rightupperleg", "righthip", "rightthigh", "r_hip", "rthigh"}},
        {"left_arm", {"lhumerus", "leftarm", "leftupperarm", "l_upperarm", "lshoulder", "leftshoulder"}},
        {"right_arm", {"rhumerus", "rightarm", "rightupperarm", "r_upperarm", "rshoulder", "rightshoulder"}},
        {"head", {"lowerneck", "neck", "neck1", "head"}},
    };
    for (const auto& [g, names] : table)
        if (g == group) return names;
    return none;
}

std::string joint_list(const Skeleton& s) {
    std::string out;
    for (const std::string& n : s.joint_names) out += (out.empty() ? "" : ", ") + n;
    return out;
}

void hide_subtree(const Skeleton& s, int top, std::vector<bool>& hidden) {
    hidden[static_cast<size_t>(top)] = true;
    for (int j = top + 1; j < s.joint_count(); ++j) {
        const int p = s.parents[static_cast<size_t>(j)];
        if (p != kNoParent && hidden[static_cast<size_t>(p)] && p >= top) hidden[static_cast<size_t>(j)] = true;
    }
}

int parse_frame_index(const std::string& text, const std::string& whole, const std::string& option) {
    char* end = nullptr;
    const long v = std::strtol(text.c_str(), &end, 10);
    if (text.empty() || end != text.c_str() + text.size() || v < 0 || v > 100000000)
        throw ImportError(option, 0, "'" + whole + "': expected A:B, two 0-based frame indices (inclusive)");
    return static_cast<int>(v);
}

quat pick(const Clip& c, int frame, int j) { return c.frame_rotations(frame)[j]; }

}  // namespace

FillMethod parse_fill_method(const std::string& text, const std::string& option) {
    if (text == "graph") return FillMethod::graph;
    if (text == "slerp") return FillMethod::slerp;
    if (text == "hold") return FillMethod::hold;
    throw ImportError(option, 0, "unknown fill method '" + text + "' (expected graph, slerp or hold)");
}

const char* fill_method_name(FillMethod m) {
    return m == FillMethod::graph ? "graph" : (m == FillMethod::slerp ? "slerp" : "hold");
}

int find_group_root(const Skeleton& s, const std::string& group) {
    for (const std::string& candidate : group_names(group))
        for (int j = 0; j < s.joint_count(); ++j)
            if (lower_bare(s.joint_names[static_cast<size_t>(j)]) == candidate) return j;
    return -1;
}

std::vector<bool> resolve_hidden_joints(const Skeleton& s, const std::string& spec, const std::string& option) {
    std::vector<bool> hidden(static_cast<size_t>(s.joint_count()), false);
    size_t begin = 0;
    bool any = false;
    while (begin <= spec.size()) {
        size_t end = spec.find(',', begin);
        if (end == std::string::npos) end = spec.size();
        std::string name = spec.substr(begin, end - begin);
        begin = end + 1;
        while (!name.empty() && name.front() == ' ') name.erase(name.begin());
        while (!name.empty() && name.back() == ' ') name.pop_back();
        if (name.empty()) continue;
        any = true;
        std::vector<std::string> groups = {name};
        if (name == "legs") groups = {"left_leg", "right_leg"};
        if (name == "arms") groups = {"left_arm", "right_arm"};
        for (const std::string& g : groups) {
            // A group name wins over a joint of that name (CMU's `head` joint vs the head group).
            int j = group_names(g).empty() ? s.find(g) : -1;
            if (!group_names(g).empty()) {
                j = find_group_root(s, g);
                if (j < 0)
                    throw ImportError(option, 0, "group '" + g + "' has no joint in this skeleton (looked for " +
                                                     group_names(g).front() + " and the common BVH names); name the joints instead");
            }
            if (j < 0)
                throw ImportError(option, 0, "no joint or group named '" + g + "' (groups: left_leg, right_leg, left_arm, right_arm, head, legs, arms; joints: " + joint_list(s) + ")");
            if (s.parents[static_cast<size_t>(j)] == kNoParent)
                throw ImportError(option, 0, "'" + g + "' is the root: the root must stay visible (the fill aligns on it)");
            hide_subtree(s, j, hidden);
        }
    }
    if (!any) throw ImportError(option, 0, "no joint given: expected comma-separated joint names or groups");
    return hidden;
}

FillGap parse_fill_frames(const std::string& text, int frame_count, const std::string& option) {
    const size_t colon = text.find(':');
    if (colon == std::string::npos)
        throw ImportError(option, 0, "'" + text + "': expected A:B, two 0-based frame indices (inclusive)");
    FillGap gap;
    gap.first = parse_frame_index(text.substr(0, colon), text, option);
    gap.last = parse_frame_index(text.substr(colon + 1), text, option);
    if (gap.first > gap.last)
        throw ImportError(option, 0, "'" + text + "': the first frame is after the last");
    if (gap.last >= frame_count)
        throw ImportError(option, 0, "'" + text + "' is out of range: the clip has " + std::to_string(frame_count) +
                                         " frames (0-based indices 0.." + std::to_string(frame_count - 1) + ")");
    return gap;
}

std::int64_t FillDatabase::frame_count() const {
    std::int64_t n = 0;
    for (const Clip& c : clips) n += c.frame_count;
    return n;
}

std::vector<vec3> model_positions_with_end_sites(const Clip& clip) {
    return model_positions_with_end_sites(clip, 0, clip.frame_count - 1);
}

std::vector<vec3> model_positions_with_end_sites(const Clip& clip, int first, int last) {
    const Skeleton& s = clip.skeleton;
    const size_t n = static_cast<size_t>(s.joint_count()), e = s.end_site_parents.size();
    std::vector<vec3> out(static_cast<size_t>(std::max(0, last - first + 1)) * (n + e));
    std::vector<quat> mr(n);
    std::vector<vec3> mp(n);
    for (int f = first; f <= last; ++f) {
        const LocalToModelJob fk{s.parents,
                                 {std::span<const quat>(clip.frame_rotations(f), n),
                                  std::span<const vec3>(clip.frame_translations(f), n)},
                                 {mr, mp}};
        (void)fk.run();  // loaded clips are validated
        vec3* row = out.data() + static_cast<size_t>(f - first) * (n + e);
        std::copy(mp.begin(), mp.end(), row);
        for (size_t k = 0; k < e; ++k) {
            const size_t p = static_cast<size_t>(s.end_site_parents[k]);
            row[n + k] = mp[p] + quat_rotate(mr[p], s.end_site_offsets[k]);
        }
    }
    return out;
}

FillDatabase prepare_fill_database(std::vector<Clip> clips, double rate) {
    FillDatabase db;
    db.rate = rate;
    if (!clips.empty()) db.skeleton = clips.front().skeleton;
    for (Clip& c : clips) {
        Clip r = c.frame_rate == rate ? std::move(c) : resample_clip(c, rate);
        std::vector<vec3> p = model_positions_with_end_sites(r);
        // Joints only: drop the end sites of each frame.
        const size_t n = static_cast<size_t>(r.joint_count()), e = r.skeleton.end_site_parents.size();
        std::vector<vec3> joints(static_cast<size_t>(r.frame_count) * n);
        for (int f = 0; f < r.frame_count; ++f)
            std::copy_n(p.begin() + static_cast<std::ptrdiff_t>(static_cast<size_t>(f) * (n + e)), n,
                        joints.begin() + static_cast<std::ptrdiff_t>(static_cast<size_t>(f) * n));
        db.positions.push_back(std::move(joints));
        db.clips.push_back(std::move(r));
    }
    return db;
}

Outcome check_fill_skeleton(const Skeleton& a, const Skeleton& b) {
    const int n = std::min(a.joint_count(), b.joint_count());
    for (int j = 0; j < n; ++j) {
        const size_t u = static_cast<size_t>(j);
        if (a.joint_names[u] != b.joint_names[u] || a.parents[u] != b.parents[u])
            return Outcome::failure("its skeleton differs from the input's at joint " + std::to_string(j) + " ('" +
                                    b.joint_names[u] + "' where the input has '" + a.joint_names[u] +
                                    "')");
    }
    if (a.joint_count() != b.joint_count())
        return Outcome::failure("its skeleton has " + std::to_string(b.joint_count()) + " joints where the input has " +
                                std::to_string(a.joint_count()) +
                                "");
    return Outcome::success();
}

std::uint64_t fill_content_hash(std::span<const std::uint8_t> bytes) { return XXH64(bytes.data(), bytes.size(), 0); }

namespace {

// The baseline value of hidden joint j at frame f: hold the last known frame
// (the next one at the clip's start), or slerp between the known frames around the gap.
quat baseline_rotation(const Clip& c, const FillGap& g, FillMethod m, int f, int j) {
    const bool before = g.first > 0, after = g.last + 1 < c.frame_count;
    if (!before && !after) return pick(c, f, j);
    if (!after || (m == FillMethod::hold && before)) return pick(c, g.first - 1, j);
    if (!before) return pick(c, g.last + 1, j);
    const float u = static_cast<float>(f - (g.first - 1)) / static_cast<float>(g.last + 1 - (g.first - 1));
    return quat_slerp(pick(c, g.first - 1, j), pick(c, g.last + 1, j), u);
}

vec3 baseline_translation(const Clip& c, const FillGap& g, int f, int j) {
    if (!c.animated_translation[static_cast<size_t>(j)]) return c.skeleton.rest_offsets[static_cast<size_t>(j)];
    const bool before = g.first > 0, after = g.last + 1 < c.frame_count;
    const auto at = [&](int frame) { return c.frame_translations(frame)[j]; };
    if (!before && !after) return at(f);
    if (!after) return at(g.first - 1);
    if (!before) return at(g.last + 1);
    const float u = static_cast<float>(f - (g.first - 1)) / static_cast<float>(g.last + 1 - (g.first - 1));
    return lerp(at(g.first - 1), at(g.last + 1), u);
}

float smoothstep01(double x) {
    const double t = std::clamp(x, 0.0, 1.0);
    return static_cast<float>(t * t * (3.0 - 2.0 * t));
}

// The capture's own jitter in the visible parents of the hidden chains. A solver
// that fits markers spreads its noise between a joint and its children: when the
// pelvis or a clavicle wobbles from one frame to the next, the true leg or arm
// turns the other way in its parent's frame and stays smooth in the world. A fill
// that is smooth in the parent's frame (a database motion, an interpolation)
// carries the wobble to the limb's end instead, amplified by its length: that is
// what the worst border moves of the 4 s gaps were (docs/fill.md). So the graph
// fill of a chain's top joint is made, and met to the known frames, in a frame
// that follows the parent's smoothed rotation; the parent's jitter — its model
// rotation against the smoothed one — is undone on the way back.
struct ParentJitter {
    std::vector<int> tops;        // hidden joints whose parent is visible
    int lo = 0;                   // first frame covered
    int radius = 1;               // of the smoothing kernel, in the clip's frames
    std::vector<quat> undo;       // per frame from lo, per top: P(f)⁻¹ · smoothed P(f)
};

quat model_rotation(const Skeleton& s, const quat* local, int j) {
    quat r = quat_identity();
    for (int k = j; k != kNoParent; k = s.parents[static_cast<size_t>(k)]) r = quat_mul(local[k], r);
    return r;
}

// model[i]⁻¹ · model smoothed around i (a triangular kernel over ±radius entries,
// clamped at the sequence's ends): the jitter that moving into the smoothed frame undoes.
quat smoothing_undo(const std::vector<quat>& model, int i, int radius) {
    const quat centre = model[static_cast<size_t>(i)];
    quat sum(0, 0, 0, 0);
    for (int d = -radius; d <= radius; ++d) {
        const quat q = model[static_cast<size_t>(std::clamp(i + d, 0, static_cast<int>(model.size()) - 1))];
        const float w = static_cast<float>(radius + 1 - std::abs(d)) * (quat_dot(q, centre) < 0.0f ? -1.0f : 1.0f);
        sum = quat(sum.w + w * q.w, sum.x + w * q.x, sum.y + w * q.y, sum.z + w * q.z);
    }
    return quat_mul(quat_conjugate(centre), quat_normalize(sum));
}

ParentJitter parent_jitter(const Clip& c, const std::vector<int>& hidden, int lo, int hi, double smooth_s) {
    ParentJitter pj;
    pj.lo = lo;
    std::vector<bool> is_hidden(static_cast<size_t>(c.joint_count()), false);
    for (int j : hidden) is_hidden[static_cast<size_t>(j)] = true;
    for (int j : hidden) {
        const int p = c.skeleton.parents[static_cast<size_t>(j)];
        if (p != kNoParent && !is_hidden[static_cast<size_t>(p)]) pj.tops.push_back(j);
    }
    pj.radius = std::max(1, static_cast<int>(smooth_s * c.frame_rate + 0.5));
    const int a = std::max(0, lo - pj.radius), b = std::min(c.frame_count - 1, hi + pj.radius);
    pj.undo.assign(static_cast<size_t>(hi - lo + 1) * pj.tops.size(), quat_identity());
    for (size_t t = 0; t < pj.tops.size(); ++t) {
        const int p = c.skeleton.parents[static_cast<size_t>(pj.tops[t])];
        std::vector<quat> model(static_cast<size_t>(b - a + 1));
        for (int f = a; f <= b; ++f) model[static_cast<size_t>(f - a)] = model_rotation(c.skeleton, c.frame_rotations(f), p);
        for (int f = lo; f <= hi; ++f)
            pj.undo[static_cast<size_t>(f - lo) * pj.tops.size() + t] = smoothing_undo(model, f - a, pj.radius);
    }
    return pj;
}

// Moves the chain tops' rotations on frames lo..hi into the smoothed parent's
// frame (`into`) or back into the parent's own frame.
void apply_parent_jitter(Clip& c, const ParentJitter& pj, bool into) {
    const size_t n = static_cast<size_t>(c.joint_count());
    const int frames = pj.tops.empty() ? 0 : static_cast<int>(pj.undo.size() / pj.tops.size());
    for (int i = 0; i < frames; ++i)
        for (size_t t = 0; t < pj.tops.size(); ++t) {
            quat& r = c.rotations[static_cast<size_t>(pj.lo + i) * n + static_cast<size_t>(pj.tops[t])];
            const quat u = pj.undo[static_cast<size_t>(i) * pj.tops.size() + t];
            r = quat_normalize(quat_mul(into ? quat_conjugate(u) : u, r));
        }
}

// One match's rotations for the hidden joints, offset so they meet the known
// frames at both borders (the offset slerps from the left border's to the
// right's across the gap). Frame-major over first..last, hidden joints in order.
std::vector<quat> matched_rotations(const Clip& clip, const FillGap& g, const FillDatabase& db, const FillMapping& m,
                                    const std::vector<int>& hidden, const ParentJitter* pj) {
    const Clip& src = db.clips[static_cast<size_t>(m.match.clip)];
    const size_t n = static_cast<size_t>(clip.joint_count());
    std::vector<quat> r(n);
    std::vector<vec3> t(n);
    const auto raw = [&](int f) { sample_clip(src, mapped_db_time(m, f / clip.frame_rate), ClipWrap::clamp, r, t); };
    // With `pj`, the database motion's chain tops move into its own smoothed
    // parents' frame too (the same kernel over the same clip frames), so a clip
    // that truly follows the database still gets its motion back exactly.
    const size_t tops = pj ? pj->tops.size() : 0;
    const int fa = pj ? std::max(0, g.first - 1 - pj->radius) : 0;
    const int fb = pj ? std::min(clip.frame_count - 1, g.last + 1 + pj->radius) : -1;
    std::vector<std::vector<quat>> parent_model(tops);
    for (int f = fa; f <= fb && tops > 0; ++f) {
        raw(f);
        for (size_t k = 0; k < tops; ++k)
            parent_model[k].push_back(model_rotation(src.skeleton, r.data(), src.skeleton.parents[static_cast<size_t>(pj->tops[k])]));
    }
    const auto sample = [&](int f) {
        raw(f);
        for (size_t k = 0; k < tops; ++k) {
            quat& q = r[static_cast<size_t>(pj->tops[k])];
            q = quat_normalize(quat_mul(quat_conjugate(smoothing_undo(parent_model[k], f - fa, pj->radius)), q));
        }
    };
    const bool before = g.first > 0, after = g.last + 1 < clip.frame_count;
    std::vector<quat> left(hidden.size(), quat_identity()), right(hidden.size(), quat_identity());
    for (int side = 0; side < 2; ++side) {
        const int f = side == 0 ? g.first - 1 : g.last + 1;
        if (side == 0 ? !before : !after) continue;
        sample(f);
        for (size_t k = 0; k < hidden.size(); ++k)
            (side == 0 ? left : right)[k] = quat_mul(pick(clip, f, hidden[k]), quat_conjugate(r[static_cast<size_t>(hidden[k])]));
    }
    if (!before) left = right;
    if (!after) right = left;
    const int span = g.last + 1 - (g.first - 1);
    std::vector<quat> out;
    for (int f = g.first; f <= g.last; ++f) {
        sample(f);
        const float u = static_cast<float>(f - (g.first - 1)) / static_cast<float>(span);
        for (size_t k = 0; k < hidden.size(); ++k)
            out.push_back(quat_normalize(quat_mul(quat_slerp(left[k], right[k], u), r[static_cast<size_t>(hidden[k])])));
    }
    return out;
}

// The graph method on top of the slerp baseline already in `clip`: the matches'
// rotations averaged (weights ∝ 1 / distance; each meets the borders, so their
// average does), then blended with the baseline for short gaps.
void apply_graph(Clip& clip, const FillGap& g, const FillDatabase& db, const std::vector<FillMapping>& matches,
                 const std::vector<int>& hidden, float weight, double ease_s, const ParentJitter* pj) {
    const size_t n = static_cast<size_t>(clip.joint_count());
    const double best = std::max(matches.front().match.distance, 1e-12);
    std::vector<quat> sum(static_cast<size_t>(g.last - g.first + 1) * hidden.size(), quat(0, 0, 0, 0));
    for (const FillMapping& m : matches) {
        const float w = static_cast<float>(best / std::max(m.match.distance, 1e-12));
        const std::vector<quat> r = matched_rotations(clip, g, db, m, hidden, pj);
        for (size_t i = 0; i < r.size(); ++i) {
            const quat q = quat_dot(sum[i], r[i]) < 0.0f ? quat(-r[i].w, -r[i].x, -r[i].y, -r[i].z) : r[i];
            sum[i] = quat(sum[i].w + w * q.w, sum[i].x + w * q.x, sum[i].y + w * q.y, sum[i].z + w * q.z);
        }
    }
    // Within `ease` frames of a border, ease in from the known motion carried on at
    // its own angular velocity, so the joints' speed does not jump at the border.
    const int length = g.last - g.first + 1;
    const int ease = std::min(static_cast<int>(ease_s * clip.frame_rate + 0.5), length / 4);
    const bool left_velocity = g.first >= 2, right_velocity = g.last + 2 < clip.frame_count;
    for (int f = g.first; f <= g.last; ++f) {
        quat* out = clip.rotations.data() + static_cast<size_t>(f) * n;
        const int dl = f - (g.first - 1), dr = (g.last + 1) - f;
        for (size_t k = 0; k < hidden.size(); ++k) {
            const size_t j = static_cast<size_t>(hidden[k]);
            quat filled = quat_normalize(sum[static_cast<size_t>(f - g.first) * hidden.size() + k]);
            // The known motion's velocity over up to 4 frames (a one-frame capture
            // glitch must not be multiplied by the ease's length), against the fill's
            // own velocity at that border; their difference, carried at most 0.3 rad,
            // corrects the fill near the border (none when the fill moves as the known
            // motion does).
            const auto correction = [&](int known, int direction, int steps) {
                int span = 1;
                while (span < 4 && known + direction * (span + 1) >= 0 && known + direction * (span + 1) < clip.frame_count &&
                       span + 1 <= length)
                    ++span;
                const quat q1 = pick(clip, known, hidden[k]);
                const int inside = known - direction * span;  // the fill's frame `span` into the gap
                const quat fill_at = quat_normalize(sum[static_cast<size_t>(inside - g.first) * hidden.size() + k]);
                const quat known_step = quat_mul(quat_conjugate(pick(clip, known + direction * span, hidden[k])), q1);
                const quat fill_step = quat_mul(quat_conjugate(fill_at), q1);
                const quat mismatch = quat_mul(fill_step, known_step);  // identity when both move alike
                double t = static_cast<double>(steps) / span;
                const double angle = quat_angle_between(quat_identity(), mismatch) * t;
                if (angle > 0.3) t *= 0.3 / angle;
                return quat_slerp(quat_identity(), mismatch, static_cast<float>(t));
            };
            if (left_velocity && dl <= ease)
                filled = quat_slerp(quat_mul(filled, correction(g.first - 1, -1, dl)), filled, smoothstep01(dl / (ease + 1.0)));
            if (right_velocity && dr <= ease)
                filled = quat_slerp(quat_mul(filled, correction(g.last + 1, +1, dr)), filled, smoothstep01(dr / (ease + 1.0)));
            out[j] = weight >= 1.0f ? filled : quat_slerp(out[j], filled, weight);
        }
    }
}

// One gap (or piece of one) filled by method `o.method`.
FillMatch fill_one_piece(Clip& clip, const FillGap& gap, const FillDatabase* db, const FillOptions& o, double graph_weight) {
    std::vector<int> hidden;
    for (int j = 0; j < clip.joint_count(); ++j)
        if (gap.hidden[static_cast<size_t>(j)]) hidden.push_back(j);
    std::vector<FillMapping> hindsight;  // evaluation only: the match chosen seeing the hidden joints
    if (o.oracle_match && o.method == FillMethod::graph && db && !db->clips.empty() && !hidden.empty()) {
        FillGap all_visible = gap;
        all_visible.hidden.assign(gap.hidden.size(), false);
        hindsight = search_fill_motion(clip, all_visible, *db, o);
    }
    const FillMethod baseline = o.method == FillMethod::hold ? FillMethod::hold : FillMethod::slerp;
    const size_t n = static_cast<size_t>(clip.joint_count());
    for (int f = gap.first; f <= gap.last; ++f)
        for (int j : hidden) {
            clip.rotations[static_cast<size_t>(f) * n + static_cast<size_t>(j)] = baseline_rotation(clip, gap, baseline, f, j);
            clip.translations[static_cast<size_t>(f) * n + static_cast<size_t>(j)] = baseline_translation(clip, gap, f, j);
        }
    FillMatch match;
    if (o.method != FillMethod::graph || !db || db->clips.empty() || hidden.empty()) return match;
    const std::vector<FillMapping> matches = o.oracle_match ? hindsight : search_fill_motion(clip, gap, *db, o);
    if (matches.empty()) return match;
    match = matches.front().match;
    match.graph_weight = graph_weight;
    if (o.parent_smooth_s <= 0.0) {
        apply_graph(clip, gap, *db, matches, hidden, static_cast<float>(match.graph_weight), o.ease_s, nullptr);
        return match;
    }
    // Fill in the smoothed parents' frame (the borders, the ease's known frames
    // and the slerp baseline with it), then move the gap's frames back; frames
    // outside the gap are not written, so they stay bit for bit.
    const int lo = std::max(0, gap.first - 5), hi = std::min(clip.frame_count - 1, gap.last + 5);
    const ParentJitter pj = parent_jitter(clip, hidden, lo, hi, o.parent_smooth_s);
    Clip work = clip;
    apply_parent_jitter(work, pj, true);
    apply_graph(work, gap, *db, matches, hidden, static_cast<float>(match.graph_weight), o.ease_s, &pj);
    apply_parent_jitter(work, pj, false);
    for (int f = gap.first; f <= gap.last; ++f)
        for (int j : hidden)
            clip.rotations[static_cast<size_t>(f) * n + static_cast<size_t>(j)] = work.rotations[static_cast<size_t>(f) * n + static_cast<size_t>(j)];
    return match;
}
}  // namespace

FillMatch fill_gap(Clip& clip, const FillGap& gap, const FillDatabase* db, const FillOptions& o) {
    const int length = gap.last - gap.first + 1;
    const double gap_s = length / clip.frame_rate;
    const double graph_weight = o.interp_blend_s > 0.0 ? smoothstep01(gap_s / o.interp_blend_s) : 1.0;
    const FillMatch whole = fill_one_piece(clip, gap, db, o, graph_weight);
    const int pieces = o.piece_s > 0.0 ? static_cast<int>(std::ceil(gap_s / o.piece_s - 1e-9)) : 1;
    // Not with the match in hindsight (the whole fill has overwritten the truth
    // that search reads), nor after no match: the pieces would read the slerp
    // baseline as the motion after them (tried: a 4.7 s gap against a 3.3 s
    // database came out at 0.7 of slerp's error, not near the truth).
    if (!whole.found || pieces <= 1 || o.oracle_match) return whole;
    // Again in pieces, in order: each piece's borders are the frame before it
    // (known, or the piece before's fill) and the whole fill's frame after it
    // (known after the last piece), and its search window on either side reads
    // those values as known: each piece is matched on its own, so database
    // motion as short as a piece (and its windows) can fill it.
    FillOptions piece_options = o;
    piece_options.coarse_stride = 2;
    for (int p = 0; p < pieces; ++p) {
        FillGap piece = gap;
        piece.first = gap.first + static_cast<int>(static_cast<std::int64_t>(length) * p / pieces);
        piece.last = gap.first + static_cast<int>(static_cast<std::int64_t>(length) * (p + 1) / pieces) - 1;
        fill_one_piece(clip, piece, db, piece_options, graph_weight);
    }
    return whole;
}

}  // namespace marionette::offline
