#include "runtime/matching/matching_database.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "runtime/math/det_math.hpp"

namespace marionette {

float MatchingWeights::of(int group) const {
    switch (group) {
        case kMatchFootPosition: return foot_position;
        case kMatchFootVelocity: return foot_velocity;
        case kMatchHipsVelocity: return hips_velocity;
        case kMatchTrajectoryPosition: return trajectory_position;
        default: return trajectory_facing;
    }
}

void MatchingDatabase::normalise(std::span<const float> raw, std::span<float> out) const {
    for (int k = 0; k < kMatchFeatureCount; ++k) {
        const size_t i = static_cast<size_t>(k);
        out[i] = (raw[i] - mean[i]) * inv_scale[i];
    }
}

namespace {

// Root ground point, facing and the feet of one source frame (metres, clip coordinates).
struct FrameBody {
    vec3 root{0.0f};       // root joint
    double heading = 0.0;
    vec3 feet[2];
};

FrameBody body_of(const MatchingSource& s, int frame, std::vector<quat>& rot, std::vector<vec3>& pos) {
    const size_t n = static_cast<size_t>(s.joint_count());
    const size_t base = static_cast<size_t>(frame) * n;
    for (size_t j = 0; j < n; ++j) {
        const quat r = s.rotations[base + j];
        const vec3 t = s.translations[base + j] * s.metres_per_unit;
        const int p = s.parents[j];
        if (p < 0) {
            rot[j] = r;
            pos[j] = t;
        } else {
            const size_t pi = static_cast<size_t>(p);
            rot[j] = quat_mul(rot[pi], r);
            pos[j] = pos[pi] + quat_rotate(rot[pi], t);
        }
    }
    FrameBody b;
    b.root = pos[0];
    const vec3 forward = quat_rotate(rot[0], vec3(0.0f, 0.0f, 1.0f));
    b.heading = det::wrap_angle(det::atan2(forward.x, forward.z) + s.facing_offset);
    b.feet[0] = pos[static_cast<size_t>(s.left_foot)];
    b.feet[1] = pos[static_cast<size_t>(s.right_foot)];
    return b;
}

Outcome check_source(const MatchingSource& s, const MatchingWeights& w) {
    const int n = s.joint_count();
    if (n <= 0) return Outcome::failure("matching database: the source has no joints");
    for (int j = 0; j < n; ++j)
        if (s.parents[static_cast<size_t>(j)] >= j || (j == 0) != (s.parents[static_cast<size_t>(j)] < 0))
            return Outcome::failure("matching database: joints are not in topological order with joint 0 the only root");
    if (s.left_foot <= 0 || s.left_foot >= n || s.right_foot <= 0 || s.right_foot >= n || s.left_foot == s.right_foot)
        return Outcome::failure("matching database: the source names no left and right foot joints");
    if (!(s.frame_rate > 0.0) || !(s.metres_per_unit > 0.0f))
        return Outcome::failure("matching database: frame rate and metres per unit must be positive");
    const size_t frames = s.rotations.size() / static_cast<size_t>(n);
    if (s.rotations.size() != frames * static_cast<size_t>(n) || s.translations.size() != s.rotations.size() ||
        s.contacts.size() != frames)
        return Outcome::failure("matching database: rotations, translations and contacts disagree on the frame count");
    if (s.clips.empty()) return Outcome::failure("matching database: no clips to match");
    for (std::span<const MatchingClipRange> ranges : {s.clips, s.actions})
        for (const MatchingClipRange& c : ranges)
            if (c.first_frame < 0 || c.frame_count < 2 ||
                static_cast<size_t>(c.first_frame) + static_cast<size_t>(c.frame_count) > frames)
                return Outcome::failure("matching database: a clip range lies outside the frames or has under 2 frames");
    for (int g = 0; g < kMatchGroupCount; ++g)
        if (!(w.of(g) >= 0.0f) || !std::isfinite(w.of(g)))
            return Outcome::failure("matching database: feature weights must be finite and not negative");
    return Outcome::success();
}

// The raw features of database frame `f` (its clip spans database frames [begin, end)).
void frame_features(const std::vector<FrameBody>& body, int begin, int end, int f,
                    const std::array<std::int32_t, kMatchTrajectoryPoints>& ahead, double rate, float* out) {
    const FrameBody& b = body[static_cast<size_t>(f)];
    double sn = 0.0, cs = 0.0;
    det::sin_cos(b.heading, sn, cs);
    const vec3 ground(b.root.x, 0.0f, b.root.z);
    const int prev = f > begin ? f - 1 : f;
    const int next = f > begin ? f : f + 1;
    const float r = static_cast<float>(rate);
    for (int i = 0; i < 2; ++i) {
        const vec3 p = to_root_frame(b.feet[i] - ground, sn, cs);
        const vec3 v = to_root_frame((body[static_cast<size_t>(next)].feet[i] - body[static_cast<size_t>(prev)].feet[i]) * r, sn, cs);
        for (int a = 0; a < 3; ++a) {
            out[kMatchGroupBegin[kMatchFootPosition] + 3 * i + a] = p[a];
            out[kMatchGroupBegin[kMatchFootVelocity] + 3 * i + a] = v[a];
        }
    }
    const vec3 hv = to_root_frame((body[static_cast<size_t>(next)].root - body[static_cast<size_t>(prev)].root) * r, sn, cs);
    for (int a = 0; a < 3; ++a) out[kMatchGroupBegin[kMatchHipsVelocity] + a] = hv[a];
    for (int k = 0; k < kMatchTrajectoryPoints; ++k) {
        const int t = f + ahead[static_cast<size_t>(k)] < end ? f + ahead[static_cast<size_t>(k)] : end - 1;
        const FrameBody& bt = body[static_cast<size_t>(t)];
        const vec3 p = to_root_frame(vec3(bt.root.x, 0.0f, bt.root.z) - ground, sn, cs);
        double fs = 0.0, fc = 0.0;
        det::sin_cos(bt.heading, fs, fc);
        const vec3 d = to_root_frame(vec3(static_cast<float>(fs), 0.0f, static_cast<float>(fc)), sn, cs);
        out[kMatchGroupBegin[kMatchTrajectoryPosition] + 2 * k] = p.x;
        out[kMatchGroupBegin[kMatchTrajectoryPosition] + 2 * k + 1] = p.z;
        out[kMatchGroupBegin[kMatchTrajectoryFacing] + 2 * k] = d.x;
        out[kMatchGroupBegin[kMatchTrajectoryFacing] + 2 * k + 1] = d.z;
    }
}

// Bounds over runs of `size` slots of the layout (padded to `boxes`), stored
// feature-major in groups of `lanes` boxes: [box / lanes][k][box % lanes].
void build_boxes(const MatchingDatabase& db, int size, size_t boxes, size_t lanes, std::vector<float>& lo, std::vector<float>& hi) {
    lo.assign(boxes * kMatchFeatureCount, std::numeric_limits<float>::infinity());
    hi.assign(boxes * kMatchFeatureCount, -std::numeric_limits<float>::infinity());
    for (size_t slot = 0; slot < db.block_frame.size(); ++slot) {
        if (db.block_frame[slot] < 0) continue;
        const size_t box = slot / static_cast<size_t>(size);
        const size_t base = (box / lanes) * lanes * kMatchFeatureCount + box % lanes;
        const float* x = db.frame_features(db.block_frame[slot]);
        for (size_t k = 0; k < kMatchFeatureCount; ++k) {
            const size_t i = base + k * lanes;
            if (x[k] < lo[i]) lo[i] = x[k];
            if (x[k] > hi[i]) hi[i] = x[k];
        }
    }
}

// Orders frames so that runs of the layout are close in feature space (a k-d
// split: the feature of widest spread, halves at multiples of a small box), which
// keeps the boxes tight. Only speed depends on it: the search's answer is the
// least (cost, frame index) whatever the order. Deterministic: ties in a feature
// go by frame index.
void kd_order(const MatchingDatabase& db, std::int32_t* begin, std::int32_t* end) {
    const std::ptrdiff_t n = end - begin;
    if (n <= kMatchSmallBox) return;
    size_t widest = 0;
    float spread = -1.0f;
    for (size_t k = 0; k < kMatchFeatureCount; ++k) {
        float lo = std::numeric_limits<float>::infinity(), hi = -lo;
        for (const std::int32_t* f = begin; f != end; ++f) {
            const float x = db.frame_features(*f)[k];
            lo = x < lo ? x : lo;
            hi = x > hi ? x : hi;
        }
        if (hi - lo > spread) spread = hi - lo, widest = k;
    }
    const std::ptrdiff_t half = ((n + 1) / 2 + kMatchSmallBox - 1) / kMatchSmallBox * kMatchSmallBox;
    std::nth_element(begin, begin + half, end, [&](std::int32_t a, std::int32_t b) {
        const float xa = db.frame_features(a)[widest], xb = db.frame_features(b)[widest];
        return xa < xb || (xa == xb && a < b);
    });
    kd_order(db, begin, begin + half);
    kd_order(db, begin + half, end);
}

void build_search_layout(MatchingDatabase& db) {
    std::vector<std::int32_t> order;
    for (std::int32_t f = 0; f < db.frame_count; ++f)
        if (db.searchable[static_cast<size_t>(f)]) order.push_back(f);
    kd_order(db, order.data(), order.data() + order.size());
    const size_t tops = (order.size() + kMatchTopBox - 1) / kMatchTopBox;
    const size_t padded = tops * kMatchTopBox;
    const size_t lanes = kMatchLanes;
    db.block_features.assign(padded * kMatchFeatureCount, 0.0f);
    db.block_frame.assign(padded, -1);
    db.block_searchable.assign(padded / lanes, 0);
    for (size_t slot = 0; slot < order.size(); ++slot) {
        const size_t block = slot / lanes, lane = slot % lanes;
        const float* x = db.frame_features(order[slot]);
        for (size_t k = 0; k < kMatchFeatureCount; ++k) db.block_features[(block * kMatchFeatureCount + k) * lanes + lane] = x[k];
        db.block_frame[slot] = order[slot];
        db.block_searchable[block] = static_cast<std::uint8_t>(db.block_searchable[block] | (1u << lane));
    }
    // Top boxes are grouped 8 to a group (rounded up), large boxes 8 to a top box, small 4 to a large box.
    const size_t top_groups = (tops + lanes - 1) / lanes;
    build_boxes(db, kMatchTopBox, top_groups * lanes, lanes, db.top_lo, db.top_hi);
    build_boxes(db, kMatchLargeBox, padded / kMatchLargeBox, lanes, db.large_lo, db.large_hi);
    build_boxes(db, kMatchSmallBox, padded / kMatchSmallBox, kMatchSmallPerLarge, db.small_lo, db.small_hi);
}

}  // namespace

void normalise_matching_database(MatchingDatabase& db, const MatchingWeights& weights) {
    const size_t frames = static_cast<size_t>(db.frame_count);
    // Mean per feature, then one standard deviation per group (the root of the
    // mean variance of its features), in frame order with double sums, over the
    // matched clips' frames (actions follow them and do not move the scales).
    const size_t stats = db.matched_frames > 0 && db.matched_frames <= db.frame_count ? static_cast<size_t>(db.matched_frames) : frames;
    std::array<double, kMatchFeatureCount> sum{};
    for (size_t f = 0; f < stats; ++f)
        for (size_t k = 0; k < kMatchFeatureCount; ++k) sum[k] += db.raw_features[f * kMatchFeatureCount + k];
    for (size_t k = 0; k < kMatchFeatureCount; ++k) db.mean[k] = stats ? static_cast<float>(sum[k] / static_cast<double>(stats)) : 0.0f;
    for (int g = 0; g < kMatchGroupCount; ++g) {
        const size_t b = static_cast<size_t>(kMatchGroupBegin[static_cast<size_t>(g)]);
        const size_t e = static_cast<size_t>(kMatchGroupBegin[static_cast<size_t>(g) + 1]);
        double var = 0.0;
        for (size_t f = 0; f < stats; ++f)
            for (size_t k = b; k < e; ++k) {
                const double d = static_cast<double>(db.raw_features[f * kMatchFeatureCount + k]) - db.mean[k];
                var += d * d;
            }
        const double count = static_cast<double>(stats) * static_cast<double>(e - b);
        const double sd = count > 0.0 ? std::sqrt(var / count) : 0.0;
        const double scale = sd > 1e-6 ? 1.0 / sd : 1.0;  // a constant group is compared in its own units
        for (size_t k = b; k < e; ++k) db.inv_scale[k] = static_cast<float>(scale * weights.of(g));
    }
    db.features.resize(db.raw_features.size());
    for (size_t f = 0; f < frames; ++f)
        db.normalise(std::span<const float>(db.raw_features.data() + f * kMatchFeatureCount, kMatchFeatureCount),
                     std::span<float>(db.features.data() + f * kMatchFeatureCount, kMatchFeatureCount));
    build_search_layout(db);
}

Outcome build_matching_database(const MatchingSource& s, const MatchingWeights& weights, MatchingDatabase& out) {
    if (Outcome ok = check_source(s, weights); !ok.ok()) return ok;
    MatchingDatabase db;
    db.joint_count = s.joint_count();
    db.frame_rate = s.frame_rate;
    for (int k = 0; k < kMatchTrajectoryPoints; ++k) {
        const long frames = std::lround(s.frame_rate * static_cast<double>(k + 1) / 3.0);
        db.trajectory_frames[static_cast<size_t>(k)] = static_cast<std::int32_t>(frames < 1 ? 1 : frames);
    }
    const std::int32_t margin = db.trajectory_frames[0];  // a jump lands with at least 1/3 s of its clip ahead
    std::vector<quat> rot(static_cast<size_t>(db.joint_count));
    std::vector<vec3> pos(static_cast<size_t>(db.joint_count));
    std::vector<FrameBody> body;
    std::vector<std::int32_t> clip_begin;
    auto add_clip = [&](const MatchingClipRange& c, bool searchable) {
        const std::int32_t begin = static_cast<std::int32_t>(db.source_frame.size());
        for (std::int32_t i = 0; i < c.frame_count; ++i) {
            db.source_frame.push_back(c.first_frame + i);
            db.clip_end.push_back(begin + c.frame_count);
            clip_begin.push_back(begin);
            db.searchable.push_back(searchable && i + margin < c.frame_count ? 1 : 0);
            body.push_back(body_of(s, c.first_frame + i, rot, pos));
        }
        return begin;
    };
    for (const MatchingClipRange& c : s.clips) add_clip(c, true);
    db.matched_frames = static_cast<std::int32_t>(db.source_frame.size());
    for (const MatchingClipRange& c : s.actions) db.action_begin.push_back(add_clip(c, false));
    db.frame_count = static_cast<std::int32_t>(db.source_frame.size());
    db.raw_features.assign(static_cast<size_t>(db.frame_count) * kMatchFeatureCount, 0.0f);
    for (std::int32_t f = 0; f < db.frame_count; ++f) {
        float* x = db.raw_features.data() + static_cast<size_t>(f) * kMatchFeatureCount;
        frame_features(body, clip_begin[static_cast<size_t>(f)], db.clip_end[static_cast<size_t>(f)], f,
                       db.trajectory_frames, s.frame_rate, x);
        for (int k = 0; k < kMatchFeatureCount; ++k)
            if (!std::isfinite(x[k]))
                return Outcome::failure("matching database: frame " + std::to_string(db.source_frame[static_cast<size_t>(f)]) +
                                        " has a feature that is not finite (bad rotations or translations)");
    }
    normalise_matching_database(db, weights);
    out = std::move(db);
    return Outcome::success();
}

}  // namespace marionette
