// The sweep's stick programs (docs/gait.md, "The envelope"): written as
// stick-program text (docs/stick-programs.md) with whole-millisecond durations
// and three-decimal values, so the text saved with --out is exactly what ran.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "app/eval/gait_sweep_detail.hpp"
#include "runtime/math/det_math.hpp"
#include "runtime/sim/tick_input.hpp"

namespace marionette::sweep_detail {

namespace {

namespace env = sweep_envelope;

enum Move { kStepTurn, kRampTurn, kReversal, kCircle, kStop, kPulses, kNoise, kNearDeadzone, kPress, kMoveCount };
constexpr int kMoveWeights[kMoveCount] = {18, 16, 10, 12, 9, 9, 9, 8, 9};  // out of 100
constexpr const char* kMoveNames[kMoveCount] = {"step turn", "ramp turn", "reversal", "circle", "stop",
                                                "pulses", "noise", "near dead zone", "press"};

struct ProgramWriter {
    SweepRandom* rng;  // a pointer, so a trial copy can be assigned back
    double first_dir;
    double deadzone;
    std::string text;
    int elapsed_ms = 0;
    double angle = 90.0;  // the left stick now: direction (degrees) and deflection
    double deflection = 0.0;
    int counts[kMoveCount] = {};

    void line(const std::string& s, int ms) {
        text += s + "\n";
        elapsed_ms += ms;
    }
    std::string stick(double a, double d) const {
        double s = 0.0, c = 0.0;
        det::sin_cos(a * det::kDegToRad, s, c);
        auto value = [](double v) { return std::fabs(v) < 0.0005 ? std::string("0") : fmt::format("{:.3f}", v); };
        return "lx=" + value(d * c) + " ly=" + value(d * s);
    }
    // hold/ramp to (a, d) for ms milliseconds.
    void set(const char* verb, int ms, double a, double d) {
        line(fmt::format("{} {}ms {}", verb, ms, stick(a, d)), ms);
        angle = a;
        deflection = d;
    }
    void hold(int ms) {
        if (ms > 0) line(fmt::format("hold {}ms", ms), ms);
    }
    int duration(int lo, int hi) { return rng->integer(lo, hi); }

    // Mostly toward the feature (within 60° of the first direction), else anywhere.
    double direction() { return rng->chance(0.55) ? first_dir + rng->uniform(-60.0, 60.0) : rng->uniform(0.0, 360.0); }
    double magnitude() {
        const double p = rng->uniform();
        if (p < 0.4) return 1.0;
        if (p < 0.75) return rng->uniform(deadzone, 1.0);
        if (p < 0.85) return near_deadzone();
        return rng->uniform(0.5, 0.95);
    }
    double near_deadzone() { return std::max(0.0, rng->uniform(deadzone - 0.04, deadzone + 0.06)); }

    void move(Move m) {
        ++counts[m];
        switch (m) {
            case kStepTurn: set("hold", duration(150, 1800), direction(), magnitude()); break;
            case kRampTurn:
                set("ramp", duration(30, 1200), direction(), magnitude());
                hold(rng->chance(0.7) ? duration(100, 1500) : 0);
                break;
            case kReversal:
                set("hold", duration(300, 2000), angle + 180.0 + (rng->chance(0.5) ? 0.0 : rng->uniform(-15.0, 15.0)),
                    rng->chance(0.5) && deflection > deadzone ? deflection : magnitude());
                break;
            case kCircle: circle(); break;
            case kStop:
                if (rng->chance(0.5)) set("hold", duration(80, 1500), angle, 0.0);
                else {
                    set("ramp", duration(30, 800), angle, 0.0);
                    hold(rng->chance(0.5) ? duration(50, 1200) : 0);
                }
                break;
            case kPulses: pulses(); break;
            case kNoise: noise(); break;
            case kNearDeadzone:
                set(rng->chance(0.5) ? "hold" : "ramp", duration(200, 1500), direction(), near_deadzone());
                break;
            case kPress: {
                const std::string_view button = kButtonNames[static_cast<std::size_t>(rng->integer(0, kButtonCount - 1))];
                const int ms = duration(10, 1500);
                line(fmt::format("press {} {}ms", button, ms), ms);
                break;
            }
            default: break;
        }
    }

    // The stick goes round: from where it is (mostly) or from a jump, any turns
    // at any rate (three turns in 0.4 s is 7.5 turns a second).
    void circle() {
        const bool continuous = rng->chance(0.7) && deflection > deadzone;
        const double from = continuous ? angle : rng->uniform(0.0, 360.0);
        const double radius = continuous ? deflection : magnitude();
        double turns = rng->uniform(0.25, 3.0);
        if (rng->chance(0.5)) turns = -turns;
        const int ms = duration(400, 4000);
        line(fmt::format("circle {}ms radius={:.3f} turns={:.3f} from={:.1f}", ms, radius, turns, from), ms);
        angle = std::fmod(from + 360.0 * turns, 360.0);
        deflection = radius;
    }

    // On and off: the same push (or a new one each time) every few hundred ms.
    void pulses() {
        const int count = rng->integer(2, 8);
        const int on = duration(80, 500), off = rng->chance(0.5) ? on : duration(80, 500);
        const bool same = rng->chance(0.7);
        double a = direction(), d = magnitude();
        for (int i = 0; i < count; ++i) {
            if (!same) {
                a = direction();
                d = magnitude();
            }
            set("hold", on, a, d);
            set("hold", off, a, 0.0);
        }
    }

    // A shaky thumb: short holds jittering around a direction.
    void noise() {
        const int count = rng->integer(5, 40);
        const double base_a = rng->chance(0.5) ? angle : direction(), base_d = rng->chance(0.5) ? deflection : magnitude();
        const double jitter_a = rng->uniform(2.0, 30.0), jitter_d = rng->uniform(0.02, 0.2);
        for (int i = 0; i < count; ++i)
            set("hold", duration(10, 60), base_a + rng->uniform(-jitter_a, jitter_a),
                std::clamp(base_d + rng->uniform(-jitter_d, jitter_d), 0.0, 1.0));
    }
};

}  // namespace

std::string make_program(SweepRandom& r, double first_dir, double deadzone, std::string& summary) {
    ProgramWriter w{&r, first_dir, deadzone, {}, 0, 90.0, 0.0, {}};
    const int total_ms = static_cast<int>(std::lround(r.uniform(env::kMinCaseS, env::kMaxCaseS) * 1000.0));
    const bool stop_at_end = r.chance(0.7);
    const int end_ms = total_ms - (stop_at_end ? 1500 : 0);
    w.hold(w.duration(0, 500));
    // Toward the feature first, so the ground is met.
    w.set(r.chance(0.7) ? "ramp" : "hold", w.duration(30, 800), first_dir, r.chance(0.6) ? 1.0 : w.magnitude());
    // Often long enough (2.5 s and more) for speed_error_pct to measure it.
    w.hold(r.chance(0.4) ? w.duration(2600, 4000) : w.duration(300, 2000));
    while (w.elapsed_ms < end_ms) {
        int pick = r.integer(0, 99), m = 0;
        while (pick >= kMoveWeights[m]) pick -= kMoveWeights[m++];
        // A move that would run past the end is cut back to a plain hold.
        ProgramWriter trial = w;
        trial.move(static_cast<Move>(m));
        if (trial.elapsed_ms > end_ms) {
            w.hold(end_ms - w.elapsed_ms);
            break;
        }
        w = trial;
    }
    if (stop_at_end) {
        w.set("ramp", w.duration(30, 500), w.angle, 0.0);
        w.hold(total_ms - w.elapsed_ms);
    }
    summary = fmt::format("{:.1f} s: approach", w.elapsed_ms / 1000.0);
    for (int m = 0; m < kMoveCount; ++m)
        if (w.counts[m]) summary += fmt::format(", {} {}", w.counts[m], kMoveNames[m]);
    if (stop_at_end) summary += ", stops at the end";
    return w.text;
}

}  // namespace marionette::sweep_detail
