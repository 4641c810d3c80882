#include "app/ui/spline_edit.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>

namespace marionette::ui {

namespace {

float& channel_of(PrototypeKey& k, int channel) { return channel == 0 ? k.x : channel == 1 ? k.y : k.z; }
float channel_of(const PrototypeKey& k, int channel) { return channel == 0 ? k.x : channel == 1 ? k.y : k.z; }

// A float as the shortest text that reads back (as the loader reads it: a
// double, then rounded to float) to the same bits; the double's text otherwise.
std::string number_text(float v) {
    char buf[64];
    auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
    (void)ec;
    double back = 0.0;
    std::from_chars(buf, end, back);
    const float again = static_cast<float>(back);
    if (std::memcmp(&again, &v, sizeof v) != 0) end = std::to_chars(buf, buf + sizeof buf, static_cast<double>(v)).ptr;
    std::string s(buf, end);
    if (s.find_first_of(".eE") == std::string::npos) s += ".0";
    return s;
}

// Where key `index`'s phase may go: strictly between its neighbours, kMinKeyGap
// from each where they leave room (never closer than it already is).
void phase_range(const SplinePrototype& p, int index, float& lo, float& hi) {
    const float cur = p.keys[static_cast<std::size_t>(index)].phase;
    lo = std::min(p.keys[static_cast<std::size_t>(index - 1)].phase + kMinKeyGap, cur);
    hi = std::max(p.keys[static_cast<std::size_t>(index + 1)].phase - kMinKeyGap, cur);
}

// A changed value on the 1e-4 grid, so saved files read 0.21, not 0.21000001
// (0.2 + 0.01 in float); an unchanged one exactly as it was.
float quantized(float value, float current) {
    if (value == current) return current;
    return std::round(value * kSplineQuantum) / kSplineQuantum;
}

}  // namespace

const char* gait_table(SplineGait gait) { return gait == SplineGait::walk ? "gait.walk" : "gait.run"; }

const char* path_key(SplinePath path) {
    return path == SplinePath::swing_foot ? "swing_foot" : path == SplinePath::pelvis ? "pelvis" : "hand";
}

SplinePrototype& prototype_of(GaitConfig& config, SplineGait gait, SplinePath path) {
    GaitPrototypes& g = gait == SplineGait::walk ? config.walk : config.run;
    return path == SplinePath::swing_foot ? g.swing_foot : path == SplinePath::pelvis ? g.pelvis : g.hand;
}

const SplinePrototype& prototype_of(const GaitConfig& config, SplineGait gait, SplinePath path) {
    return prototype_of(const_cast<GaitConfig&>(config), gait, path);
}

bool phase_editable(const SplinePrototype& p, int index) { return index > 0 && index + 1 < p.count; }

bool values_editable(const SplinePrototype& p, SplinePath path, int index) {
    if (index < 0 || index >= p.count) return false;
    return path_loops(path) || phase_editable(p, index);
}

bool set_key(SplinePrototype& p, SplinePath path, int index, float phase, int channel, float value) {
    if (index < 0 || index >= p.count || p.count < 2 || channel < 0 || channel > 2) return false;
    if (!std::isfinite(phase) || !std::isfinite(value)) return false;
    const SplinePrototype before = p;
    PrototypeKey& k = p.keys[static_cast<std::size_t>(index)];
    if (phase_editable(p, index)) {
        float lo = 0.0f, hi = 0.0f;
        phase_range(p, index, lo, hi);
        k.phase = std::clamp(quantized(phase, k.phase), lo, hi);
    }
    if (values_editable(p, path, index)) {
        const float cur = channel_of(k, channel);
        const float v =
            std::clamp(quantized(value, cur), std::min(-kSplineValueLimit, cur), std::max(kSplineValueLimit, cur));
        channel_of(k, channel) = v;
        // A looping path's ends are one point: both move.
        if (path_loops(path) && (index == 0 || index == p.count - 1)) {
            channel_of(p.keys[0], channel) = v;
            channel_of(p.keys[static_cast<std::size_t>(p.count - 1)], channel) = v;
        }
    }
    return !(p == before);
}

bool move_key(SplinePrototype& p, SplinePath path, int index, float dphase, int channel, float dvalue) {
    if (index < 0 || index >= p.count || channel < 0 || channel > 2) return false;
    if (!std::isfinite(dphase) || !std::isfinite(dvalue)) return false;
    const PrototypeKey& k = p.keys[static_cast<std::size_t>(index)];
    return set_key(p, path, index, k.phase + dphase, channel, channel_of(k, channel) + dvalue);
}

std::string validate_prototype(const SplinePrototype& p, SplinePath path) {
    if (p.count < 2 || p.count > kMaxPrototypeKeys) return "expected 2 to 8 keys";
    for (int i = 0; i < p.count; ++i) {
        const PrototypeKey& k = p.keys[static_cast<std::size_t>(i)];
        for (float v : {k.phase, k.x, k.y, k.z})
            if (!std::isfinite(v) || std::fabs(v) > 10.0f) return "key " + std::to_string(i) + ": values must be finite and within ±10";
        if (i > 0 && !(k.phase > p.keys[static_cast<std::size_t>(i - 1)].phase))
            return "key " + std::to_string(i) + ": phases must increase from key to key";
    }
    const PrototypeKey& first = p.keys[0];
    const PrototypeKey& last = p.keys[static_cast<std::size_t>(p.count - 1)];
    if (first.phase != 0.0f || last.phase != 1.0f) return "the first key's phase must be 0 and the last key's 1";
    if (!path_loops(path) && !(first.x == 0.0f && first.y == 0.0f && first.z == 0.0f && last.x == 0.0f &&
                               last.y == 0.0f && last.z == 1.0f))
        return "a swing must start at [0, 0, 0, 0] and end at [1, 0, 0, 1]";
    if (path_loops(path) && !(first.x == last.x && first.y == last.y && first.z == last.z))
        return "a looping path must end with the values it starts with";
    return {};
}

std::string prototype_toml(const SplinePrototype& p) {
    std::string out = "[";
    for (int i = 0; i < p.count; ++i) {
        const PrototypeKey& k = p.keys[static_cast<std::size_t>(i)];
        out += std::string(i ? ", " : "") + "[" + number_text(k.phase) + ", " + number_text(k.x) + ", " +
               number_text(k.y) + ", " + number_text(k.z) + "]";
    }
    return out + "]";
}

}  // namespace marionette::ui
