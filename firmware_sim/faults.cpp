#include "firmware_sim/faults.hpp"

#include <charconv>
#include <cmath>

#include "runtime/errors/import_error.hpp"
#include "runtime/math/splitmix64.hpp"

namespace marionette::firmware_sim {

namespace {
[[noreturn]] void fail(std::string_view item, const std::string& what) {
    throw ImportError("--faults", 0, "'" + std::string(item) + "': " + what);
}
double parse_number(std::string_view item, std::string_view text) {
    double v = 0.0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(v)) fail(item, "expected a number");
    return v;
}
double parse_probability(std::string_view item, std::string_view text) {
    const double v = parse_number(item, text);
    if (v < 0.0 || v > 1.0) fail(item, "expected a probability in [0, 1]");
    return v;
}
// 1.5s, 200ms, 50us
double parse_duration(std::string_view item, std::string_view text) {
    double scale = 1.0;
    if (text.ends_with("ms")) { scale = 1e-3; text.remove_suffix(2); }
    else if (text.ends_with("us")) { scale = 1e-6; text.remove_suffix(2); }
    else if (text.ends_with("s")) { text.remove_suffix(1); }
    else fail(item, "expected a duration with a unit (s, ms or us)");
    const double v = parse_number(item, text) * scale;
    if (v < 0.0) fail(item, "expected a duration >= 0");
    return v;
}
}  // namespace

bool FaultSpec::any() const {
    return noise > 0 || drift != 0 || quant_bits > 0 || jitter_s > 0 || drop > 0 || duplicate > 0 || corrupt > 0 ||
           unplug_at_s >= 0 || !syn_dropped_at_s.empty();
}

FaultSpec parse_faults(std::string_view list) {
    FaultSpec f;
    while (!list.empty()) {
        const std::size_t comma = list.find(',');
        const std::string_view item = list.substr(0, comma);
        list = comma == std::string_view::npos ? std::string_view() : list.substr(comma + 1);
        if (item.empty()) continue;
        const std::size_t eq = item.find('=');
        if (eq == std::string_view::npos)
            fail(item, "expected NAME=VALUE (noise, drift, quant, jitter, drop, dup, corrupt, unplug, syn_dropped, seed)");
        const std::string_view name = item.substr(0, eq), value = item.substr(eq + 1);
        if (name == "noise") {
            f.noise = parse_number(item, value);
            if (f.noise < 0 || f.noise > 1) fail(item, "expected a standard deviation in [0, 1]");
        } else if (name == "drift") {
            f.drift = parse_number(item, value);
            if (std::fabs(f.drift) > 0.5) fail(item, "expected a drift in [-0.5, 0.5]");
        } else if (name == "quant") {
            const double bits = parse_number(item, value);
            if (bits != std::floor(bits) || bits < 2 || bits > 16) fail(item, "expected a whole number of bits in [2, 16]");
            f.quant_bits = static_cast<int>(bits);
        } else if (name == "jitter") {
            f.jitter_s = parse_duration(item, value);
        } else if (name == "drop") {
            f.drop = parse_probability(item, value);
        } else if (name == "dup") {
            f.duplicate = parse_probability(item, value);
        } else if (name == "corrupt") {
            f.corrupt = parse_probability(item, value);
        } else if (name == "unplug") {
            const std::size_t plus = value.find('+');
            if (plus == std::string_view::npos) fail(item, "expected unplug=AT+FOR, e.g. unplug=2s+500ms");
            f.unplug_at_s = parse_duration(item, value.substr(0, plus));
            f.unplug_for_s = parse_duration(item, value.substr(plus + 1));
        } else if (name == "syn_dropped") {
            f.syn_dropped_at_s.push_back(parse_duration(item, value));
        } else if (name == "seed") {
            const double s = parse_number(item, value);
            if (s < 0 || s != std::floor(s) || s > 9.0e15) fail(item, "expected a whole number >= 0");
            f.seed = static_cast<std::uint64_t>(s);
        } else {
            fail(item, "unknown fault (expected noise, drift, quant, jitter, drop, dup, corrupt, unplug, syn_dropped, seed)");
        }
    }
    return f;
}

std::string describe_faults(const FaultSpec& f) {
    std::string out;
    const auto add = [&](const std::string& s) { out += (out.empty() ? "" : ",") + s; };
    if (f.noise > 0) add("noise=" + std::to_string(f.noise));
    if (f.drift != 0) add("drift=" + std::to_string(f.drift));
    if (f.quant_bits > 0) add("quant=" + std::to_string(f.quant_bits));
    if (f.jitter_s > 0) add("jitter=" + std::to_string(f.jitter_s) + "s");
    if (f.drop > 0) add("drop=" + std::to_string(f.drop));
    if (f.duplicate > 0) add("dup=" + std::to_string(f.duplicate));
    if (f.corrupt > 0) add("corrupt=" + std::to_string(f.corrupt));
    if (f.unplug_at_s >= 0) add("unplug=" + std::to_string(f.unplug_at_s) + "s+" + std::to_string(f.unplug_for_s) + "s");
    for (double t : f.syn_dropped_at_s) add("syn_dropped=" + std::to_string(t) + "s");
    add("seed=" + std::to_string(f.seed));
    return out;
}

std::uint64_t SimRandom::next_u64() { return splitmix64_next(state_); }
double SimRandom::uniform() { return splitmix64_unit(state_); }
double SimRandom::gaussian() {
    const double u1 = 1.0 - uniform(), u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
}

}  // namespace marionette::firmware_sim
