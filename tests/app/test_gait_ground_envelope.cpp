// The gait over the ground envelope of docs/gait.md ("Ground"), as generated
// cases with fixed seeds: random stairs (rise 10–22 cm, tread 25–40 cm, one or
// two flights with a landing, up and down, approached at 0–60° off the stairs'
// axis), random ramps and hillsides up to 30° walked at a random heading,
// random heightfields with ±30 cm of relief over 2 m, random curbs and ledges up
// to 0.35 m up and down — each at a random walk or run speed, and each held to
// every limit of gait-eval (app/eval/gait_eval.cpp). A generated case that ever
// failed stays in kRegressionCases.
#include <catch2/catch.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

#include "app/config/config.hpp"
#include "app/eval/gait_eval.hpp"
#include "app/eval/gait_sweep.hpp"
#include "runtime/formats/stick_program.hpp"

using namespace marionette;

namespace {

// The sweep's SplitMix64 (app/eval/gait_sweep.hpp): a seed gives the same case everywhere.
using Rng = SweepRandom;

enum class Ground { stairs, slope, heightfield, curb };

struct Case {
    std::string name;
    Terrain terrain;
    std::string program;
    bool check_speed = true;
};

// A stick program: settle, ramp to (lx, ly), hold, release, settle.
std::string walk_program(double lx, double ly, double hold_s) {
    return fmt::format("hold 300ms\nramp 400ms lx={:.4f} ly={:.4f}\nhold {}ms\nramp 300ms lx=0 ly=0\nhold 800ms\n", lx, ly,
                       static_cast<int>(hold_s * 1000.0));
}

// Stairs along −Z (the stick's up), spanning x: flights of `steps` risers with
// landings between; descending ones start on a platform at the top.
Case stairs_case(Rng& rng) {
    const double rise = rng.uniform(0.10, 0.22), tread = rng.uniform(0.25, 0.40);
    const int flights = rng.integer(1, 2), steps = rng.integer(3, 8);
    const double landing = rng.uniform(0.9, 1.6);
    const bool up = rng.coin();
    const double angle = rng.uniform(0.0, 60.0) * (rng.coin() ? 1.0 : -1.0);
    const double deflection = rng.uniform(0.45, 1.0);
    const double top = rise * flights * steps;
    Terrain t;
    double z = -1.3, h = up ? 0.0 : top;
    auto add = [&](double length, double height) {
        if (height > 1e-4) t.boxes.push_back({-40.0f, static_cast<float>(z - length), 40.0f, static_cast<float>(z), static_cast<float>(height)});
        z -= length;
    };
    if (!up) t.boxes.push_back({-40.0f, -1.3f, 40.0f, 40.0f, static_cast<float>(top)});
    for (int f = 0; f < flights; ++f) {
        for (int s = 0; s < steps; ++s) {
            h += up ? rise : -rise;
            add(tread, h);
        }
        if (f + 1 < flights) add(landing - tread, h);
    }
    add(30.0, h);
    const double a = angle * 3.14159265358979 / 180.0;
    // Long enough to cross the flights at the capped stair speed.
    const double hold = 3.0 + 0.8 * (flights * steps * tread + (flights - 1) * landing);
    Case c{fmt::format("stairs rise {:.3f} tread {:.3f} {}x{} landing {:.2f} {} at {:.0f} deg, stick {:.2f}", rise, tread,
                       flights, steps, landing, up ? "up" : "down", angle, deflection),
           std::move(t), walk_program(deflection * std::sin(a), deflection * std::cos(a), hold)};
    return c;
}

// A plane of up to 30° over the whole walk, with its fall line at a random
// heading, walked at another random heading (up, down, across).
Case slope_case(Rng& rng) {
    const double degrees = rng.uniform(0.0, 30.0), fall = rng.uniform(0.0, 6.2831853), heading = rng.uniform(0.0, 6.2831853);
    const double deflection = rng.uniform(0.45, 1.0);
    const double g = std::tan(degrees * 3.14159265358979 / 180.0);
    const double gx = g * std::cos(fall), gz = g * std::sin(fall);
    const double span = 80.0;
    Terrain t;
    const double base = 0.01 - std::min(0.0, gx * span) - std::min(0.0, gz * span);
    t.slopes.push_back({-40.0f, -40.0f, 40.0f, 40.0f, static_cast<float>(base), static_cast<float>(gx), static_cast<float>(gz)});
    return {fmt::format("slope {:.1f} deg falling toward {:.2f} rad, walked at {:.2f} rad, stick {:.2f}", degrees, fall, heading,
                        deflection),
            std::move(t), walk_program(deflection * std::sin(heading), deflection * std::cos(heading), 4.0)};
}

// Outdoor ground: random heights in ±0.3 m on knots 2 m apart, eased between
// them (smoothstep) onto a 0.25 m grid.
Case heightfield_case(Rng& rng) {
    constexpr int knots = 13;  // 24 m
    double k[knots][knots];
    for (auto& row : k)
        for (double& v : row) v = rng.uniform(-0.3, 0.3);
    const double heading = rng.uniform(0.0, 6.2831853), deflection = rng.uniform(0.45, 1.0);
    Terrain t;
    Heightfield& hf = t.heightfield;
    hf.origin_x = -12.0f;
    hf.origin_z = -12.0f;
    hf.cell = 0.25f;
    hf.nx = hf.nz = 97;
    hf.heights.resize(static_cast<std::size_t>(hf.nx * hf.nz));
    const auto ease = [](double u) { return u * u * (3.0 - 2.0 * u); };
    for (int iz = 0; iz < hf.nz; ++iz)
        for (int ix = 0; ix < hf.nx; ++ix) {
            const double u = ix * 0.125, v = iz * 0.125;  // knot units
            const int i = std::min(static_cast<int>(u), knots - 2), j = std::min(static_cast<int>(v), knots - 2);
            const double fu = ease(u - i), fv = ease(v - j);
            const double a = k[j][i] + (k[j][i + 1] - k[j][i]) * fu, b = k[j + 1][i] + (k[j + 1][i + 1] - k[j + 1][i]) * fu;
            hf.heights[static_cast<std::size_t>(iz * hf.nx + ix)] = static_cast<float>(a + (b - a) * fv);
        }
    return {fmt::format("heightfield, walked at {:.2f} rad, stick {:.2f}", heading, deflection), std::move(t),
            walk_program(deflection * std::sin(heading), deflection * std::cos(heading), 3.0)};
}

// A curb (step up onto a box) or a ledge (step down off one), up to 0.35 m,
// its edge 1–2 m ahead, approached at 0–60°.
Case curb_case(Rng& rng) {
    const double height = rng.uniform(0.05, 0.35), edge = -rng.uniform(1.0, 2.0);
    const bool up = rng.coin();
    const double angle = rng.uniform(0.0, 60.0) * (rng.coin() ? 1.0 : -1.0), deflection = rng.uniform(0.45, 1.0);
    Terrain t;
    if (up) t.boxes.push_back({-40.0f, -40.0f, 40.0f, static_cast<float>(edge), static_cast<float>(height)});
    else t.boxes.push_back({-40.0f, static_cast<float>(edge), 40.0f, 40.0f, static_cast<float>(height)});
    const double a = angle * 3.14159265358979 / 180.0;
    return {fmt::format("{} {:.3f} m at {:.2f} m, {:.0f} deg, stick {:.2f}", up ? "curb" : "ledge", height, edge, angle, deflection),
            std::move(t), walk_program(deflection * std::sin(a), deflection * std::cos(a), 3.0)};
}

Case make_case(Ground kind, std::uint64_t seed) {
    Rng rng(seed * 0x100000001B3ull + static_cast<std::uint64_t>(kind));
    switch (kind) {
        case Ground::stairs: return stairs_case(rng);
        case Ground::slope: return slope_case(rng);
        case Ground::heightfield: return heightfield_case(rng);
        case Ground::curb: return curb_case(rng);
    }
    return {};
}

struct Worst {
    double skate = 0.0, penetration = 0.0, joint_speed = 0.0, speed_error = 0.0;
    std::uint64_t skate_seed = 0, penetration_seed = 0, joint_speed_seed = 0, speed_error_seed = 0;
    void add(const GaitMetrics& m, std::uint64_t seed) {
        auto keep = [&](double value, double& worst, std::uint64_t& at) {
            if (value > worst) {
                worst = value;
                at = seed;
            }
        };
        keep(m.foot_skate_mm, skate, skate_seed);
        keep(m.penetration_mm, penetration, penetration_seed);
        keep(m.max_joint_speed_deg_s, joint_speed, joint_speed_seed);
        keep(m.speed_error_pct, speed_error, speed_error_seed);
    }
};

GaitMetrics check_case(Ground kind, std::uint64_t seed) {
    const Case c = make_case(kind, seed);
    SimConfig config = default_config().sim;
    config.terrain = c.terrain;
    config.terrain_name = c.name;
    const GaitMetrics m = evaluate_gait(config, parse_stick_program(c.program, "generated.prog"));
    INFO(fmt::format("seed {}: {}\n  skate {:.3f} mm (tick {}), penetration {:.3f} mm ({} at tick {}), joint speed {:.0f} deg/s "
                     "({} at tick {}), speed error {:.2f} % over {} holds",
                     seed, c.name, m.foot_skate_mm, m.skate_tick, m.penetration_mm, m.deepest_point, m.deepest_tick,
                     m.max_joint_speed_deg_s, m.fastest_joint, m.fastest_joint_tick, m.speed_error_pct, m.speed_windows));
    CHECK(m.steps >= 2);
    CHECK(m.foot_skate_mm < kMaxFootSkateMm);
    CHECK(m.penetration_mm < kMaxPenetrationMm);
    CHECK(m.max_joint_speed_deg_s < kMaxJointSpeedDegS);
    if (c.check_speed) CHECK(m.speed_error_pct < kMaxSpeedErrorPct);
    return m;
}

constexpr int kCasesPerKind = 12;

// Generated seeds (of the 100 per kind of the wider sweep) that do not meet
// every limit yet — max joint speed on stairs and one curb (the slope and
// heightfield seeds that skated, entered the ground or spun a joint meet every
// limit since stranded swings re-aim, and are kept as regressions): they run in the "[!mayfail]" test below, which
// reports them without failing the run, until the gait meets them; then they
// move back into the must-pass set. docs/gait.md lists them.
struct KnownFailure {
    Ground kind;
    std::uint64_t seed;
};
// None now: stairs seeds 6 and 40 (1653 °/s, a late-lifted swing with the
// cycle's last hundredths of a second for its travel) meet every limit since a
// swing takes at least its travel at 4 m/s (branch gait3) and are kept as
// regressions, as the 14 other stairs seeds and curb seed 74 are since the
// pelvis sinks in time for a landing.
constexpr std::array<KnownFailure, 0> kKnownFailures{};
bool known_failure(Ground kind, std::uint64_t seed) {
    for (const KnownFailure& k : kKnownFailures)
        if (k.kind == kind && k.seed == seed) return true;
    return false;
}

// Every generated case of a kind (seeds 1..cases, less the known failures) and
// the kind's regression seeds; prints the worst value of each metric.
void check_kind(Ground kind, const char* name, std::initializer_list<std::uint64_t> regressions, int cases = kCasesPerKind,
                bool skip_known = true) {
    Worst worst;
    int run = 0;
    for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(cases); ++seed) {
        if (skip_known && known_failure(kind, seed)) continue;
        worst.add(check_case(kind, seed), seed);
        ++run;
    }
    for (std::uint64_t seed : regressions) {
        worst.add(check_case(kind, seed), seed);
        ++run;
    }
    fmt::print("ground envelope, {}: {} cases; worst skate {:.4f} mm (seed {}), penetration {:.4f} mm (seed {}), joint speed "
               "{:.0f} deg/s (seed {}), speed error {:.2f} % (seed {})\n",
               name, run, worst.skate, worst.skate_seed, worst.penetration, worst.penetration_seed, worst.joint_speed,
               worst.joint_speed_seed, worst.speed_error, worst.speed_error_seed);
}

}  // namespace

TEST_CASE("gait ground envelope: generated stairs, up and down, at any angle to 60 degrees", "[gait_ground]") {
    check_kind(Ground::stairs, "stairs", {37, 52, 4, 10, 11, 13, 15, 21, 27, 44, 54, 78, 86, 89, 93, 95, 6, 40});
}

TEST_CASE("gait ground envelope: generated ramps and hillsides to 30 degrees, at any heading", "[gait_ground]") {
    check_kind(Ground::slope, "ramps and hillsides", {23, 28, 33, 35, 37, 47, 51, 53, 60, 61, 69, 70, 75, 76, 84, 90, 95, 100});
}

TEST_CASE("gait ground envelope: generated heightfields with 30 cm of relief", "[gait_ground]") {
    check_kind(Ground::heightfield, "heightfields", {25, 28, 32, 56, 60, 73, 89, 91});
}

TEST_CASE("gait ground envelope: generated curbs and ledges to 0.35 m", "[gait_ground]") {
    check_kind(Ground::curb, "curbs and ledges", {74});
}

TEST_CASE("gait ground envelope: generated cases that still exceed a limit (regressions, reported)", "[gait_ground][!mayfail]") {
    for (const KnownFailure& k : kKnownFailures) check_case(k.kind, k.seed);
}

// The wider sweep, not run by CI (hidden tag): 100 cases of each kind, known
// failures included, for measuring the envelope after a change.
TEST_CASE("gait ground envelope: wider sweep, 100 cases per kind", "[.gait_ground_sweep]") {
    check_kind(Ground::stairs, "stairs", {}, 100, false);
    check_kind(Ground::slope, "ramps and hillsides", {}, 100, false);
    check_kind(Ground::heightfield, "heightfields", {}, 100, false);
    check_kind(Ground::curb, "curbs and ledges", {}, 100, false);
}
