// The sweep's case generator (app/eval/gait_sweep.hpp; docs/gait.md, "The
// envelope"): a terrain drawn along an axis (a "profile" of boxes and slope
// patches, or a hillside plane, or a heightfield) and a stick program written
// as stick-program text, then parsed, so what is evaluated is what --out saves.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "app/eval/gait_sweep_detail.hpp"
#include "runtime/math/det_math.hpp"
#include "runtime/sim/tick_input.hpp"

namespace marionette {

namespace env = sweep_envelope;

const char* sweep_ground_name(SweepGround ground) {
    switch (ground) {
        case SweepGround::flat: return "flat";
        case SweepGround::stairs: return "stairs";
        case SweepGround::ramp: return "ramp";
        case SweepGround::hillside: return "hillside";
        case SweepGround::heightfield: return "heightfield";
        case SweepGround::curb: return "curb";
        case SweepGround::wall: return "wall";
    }
    return "?";
}

namespace {

double wrap_deg(double a) {
    while (a > 180.0) a -= 360.0;
    while (a <= -180.0) a += 360.0;
    return a;
}

// ---- terrain, in the coordinates of an axis ------------------------------------
// u: distance along the axis from the puppet's start; w: distance across it. The
// axis is one of the four world directions, so every box and slope stays
// axis-aligned (the terrain format's boxes are) and the conversion is exact.
struct Axis {
    double dx = 0.0, dz = -1.0;   // world (x, z) of +u
    double lx = -1.0, lz = 0.0;   // world (x, z) of +w
};

Axis axis_from_deg(double axis_deg) {
    // Stick angle a walks toward world (cos a, −sin a); +w is a + 90°.
    const int quarter = static_cast<int>(std::lround(axis_deg / 90.0)) & 3;
    static constexpr double kDir[4][2] = {{1, 0}, {0, -1}, {-1, 0}, {0, 1}};
    Axis a;
    a.dx = kDir[quarter][0];
    a.dz = kDir[quarter][1];
    a.lx = kDir[(quarter + 1) & 3][0];
    a.lz = kDir[(quarter + 1) & 3][1];
    return a;
}

struct Footprint {
    float min_x, min_z, max_x, max_z;
};

Footprint footprint(const Axis& a, double u0, double u1, double w0, double w1) {
    const double xs[2] = {u0 * a.dx + w0 * a.lx, u1 * a.dx + w1 * a.lx};
    const double zs[2] = {u0 * a.dz + w0 * a.lz, u1 * a.dz + w1 * a.lz};
    return {static_cast<float>(std::min(xs[0], xs[1])), static_cast<float>(std::min(zs[0], zs[1])),
            static_cast<float>(std::max(xs[0], xs[1])), static_cast<float>(std::max(zs[0], zs[1]))};
}

void add_box(Terrain& t, const Axis& a, double u0, double u1, double w0, double w1, double top) {
    const Footprint f = footprint(a, u0, u1, w0, w1);
    t.boxes.push_back({f.min_x, f.min_z, f.max_x, f.max_z, static_cast<float>(top)});
}

// A band across the whole ground from u0 to u1 at height `top` (nothing at 0).
void add_band(Terrain& t, const Axis& a, double u0, double u1, double top) {
    if (top > 0.0) add_box(t, a, u0, u1, -env::kGroundHalfSpanM, env::kGroundHalfSpanM, top);
}

// A slope band: height h0 at u0, rising `grade` per metre of u, up to u1.
void add_slope_band(Terrain& t, const Axis& a, double u0, double u1, double h0, double grade) {
    const Footprint f = footprint(a, u0, u1, -env::kGroundHalfSpanM, env::kGroundHalfSpanM);
    TerrainSlope s{f.min_x, f.min_z, f.max_x, f.max_z, 0.0f, static_cast<float>(grade * a.dx), static_cast<float>(grade * a.dz)};
    s.base = static_cast<float>(h0 + grade * (a.dx * f.min_x + a.dz * f.min_z - u0));
    t.slopes.push_back(s);
}

double tan_deg(double degrees) {
    double s = 0.0, c = 0.0;
    det::sin_cos(degrees * det::kDegToRad, s, c);
    return s / c;
}

// Half the cases lean to the hard end of a range.
double draw_hard(SweepRandom& r, double lo, double hard_lo, double hi) {
    return r.chance(0.5) ? r.uniform(hard_lo, hi) : r.uniform(lo, hi);
}

double draw_off_axis(SweepRandom& r) {
    const double a = r.chance(0.3) ? r.uniform(45.0, env::kMaxOffAxisDeg) : r.uniform(0.0, env::kMaxOffAxisDeg);
    return r.chance(0.5) ? a : -a;
}

// Flights of stairs up to a platform and down again (or, started on top, down
// only). A flight of n risers has n − 1 treads and ends on a landing.
std::string make_stairs(SweepRandom& r, SweepGroundParams& g, Terrain& t) {
    const Axis a = axis_from_deg(g.axis_deg);
    g.rise_m = draw_hard(r, 0.06, 0.16, env::kMaxStairRiseM);
    g.tread_m = r.chance(0.5) ? r.uniform(env::kMinStairTreadM, 0.30) : r.uniform(env::kMinStairTreadM, env::kMaxTreadM);
    g.risers_per_flight = r.chance(0.3) ? 8 : r.integer(2, 12);
    g.flights = r.integer(1, 3);
    g.landing_m = r.uniform(0.9, 2.0);
    g.start_on_top = r.chance(0.35);
    const double top_length = r.uniform(1.5, 4.0);
    const double height = g.rise_m * g.risers_per_flight * g.flights;
    double u = r.uniform(g.start_on_top ? 0.8 : 1.0, g.start_on_top ? 2.5 : 4.0);
    if (!g.start_on_top) {
        for (int f = 0; f < g.flights; ++f) {
            for (int k = 1; k < g.risers_per_flight; ++k, u += g.tread_m)
                add_band(t, a, u, u + g.tread_m, g.rise_m * (f * g.risers_per_flight + k));
            const double landing = f + 1 == g.flights ? top_length : g.landing_m;
            add_band(t, a, u, u + landing, g.rise_m * (f + 1) * g.risers_per_flight);
            u += landing;
        }
    } else {
        add_band(t, a, -env::kGroundHalfSpanM, u, height);
    }
    for (int f = 0; f < g.flights; ++f) {
        const double flight_top = height - g.rise_m * f * g.risers_per_flight;
        for (int k = 1; k < g.risers_per_flight; ++k, u += g.tread_m)
            add_band(t, a, u, u + g.tread_m, flight_top - g.rise_m * k);
        if (f + 1 < g.flights) {
            add_band(t, a, u, u + g.landing_m, flight_top - g.rise_m * g.risers_per_flight);
            u += g.landing_m;
        }
    }
    return fmt::format("stairs: rise {:.3f} m, tread {:.3f} m, {} flight(s) of {} risers, landings {:.2f} m, {}",
                       g.rise_m, g.tread_m, g.flights, g.risers_per_flight, g.landing_m,
                       g.start_on_top ? "starting on top (down first)" : "up, then down");
}

// A ramp up to a plateau and down again (or, started on the plateau, down).
std::string make_ramp(SweepRandom& r, SweepGroundParams& g, Terrain& t) {
    const Axis a = axis_from_deg(g.axis_deg);
    g.slope_deg = draw_hard(r, 3.0, 20.0, env::kMaxSlopeDeg);
    g.start_on_top = r.chance(0.35);
    const double grade = tan_deg(g.slope_deg);
    const double length = r.uniform(2.0, 8.0);
    const double height = grade * length;
    double u = r.uniform(1.0, 4.0);
    if (!g.start_on_top) {
        add_slope_band(t, a, u, u + length, 0.0, grade);
        u += length;
        const double plateau = r.uniform(1.0, 4.0);
        add_band(t, a, u, u + plateau, height);
        u += plateau;
    } else {
        add_band(t, a, -env::kGroundHalfSpanM, u, height);
    }
    add_slope_band(t, a, u, u + length, height, -grade);
    return fmt::format("ramp: {:.1f}°, {:.1f} m long, {:.2f} m high, {}", g.slope_deg, length, height,
                       g.start_on_top ? "starting on top (down first)" : "up, plateau, down");
}

// One plane over the whole reachable ground, rising toward axis_deg (any angle).
std::string make_hillside(SweepRandom& r, SweepGroundParams& g, Terrain& t, double first_dir) {
    g.slope_deg = draw_hard(r, 3.0, 20.0, env::kMaxSlopeDeg);
    const int way = r.integer(0, 3);  // walked up, down, across, or at any angle
    static constexpr double kOffset[3] = {0.0, 180.0, 90.0};
    const double offset = way == 3 ? r.uniform(0.0, 360.0) : kOffset[way] + r.uniform(-20.0, 20.0);
    g.axis_deg = wrap_deg(first_dir - (way == 2 && r.chance(0.5) ? -offset : offset));
    g.approach_deg = wrap_deg(first_dir - g.axis_deg);
    double s = 0.0, c = 0.0;
    det::sin_cos(g.axis_deg * det::kDegToRad, s, c);
    const double grade = tan_deg(g.slope_deg);
    const float span = static_cast<float>(env::kGroundHalfSpanM);
    TerrainSlope plane{-span, -span, span, span, 0.0f, static_cast<float>(grade * c), static_cast<float>(-grade * s)};
    plane.base = static_cast<float>(std::max(0.0, -2.0 * span * plane.grade_x) + std::max(0.0, -2.0 * span * plane.grade_z));
    t.slopes.push_back(plane);
    static constexpr const char* kWay[4] = {"walked up", "walked down", "walked across", "walked at any angle"};
    return fmt::format("hillside: {:.1f}°, {} ({:.0f}° from uphill)", g.slope_deg, kWay[way], g.approach_deg);
}

// Value noise: random heights on a lattice relief_span apart, blended with
// smoothstep, sampled on a 0.25 m grid; scaled down if any grade passes 30°.
std::string make_heightfield(SweepRandom& r, SweepGroundParams& g, Terrain& t) {
    g.relief_m = draw_hard(r, 0.05, 0.2, env::kMaxReliefM);
    g.relief_span_m = r.uniform(env::kMinReliefSpanM, 4.0);
    constexpr double kHalf = 16.0, kCell = 0.25;
    const int n = static_cast<int>(2.0 * kHalf / kCell) + 1;
    const int lattice = static_cast<int>(2.0 * kHalf / g.relief_span_m) + 2;
    std::vector<double> values(static_cast<std::size_t>(lattice * lattice));
    for (double& v : values) v = r.uniform(-g.relief_m, g.relief_m);
    auto smooth = [](double x) { return x * x * (3.0 - 2.0 * x); };
    Heightfield& hf = t.heightfield;
    hf.origin_x = static_cast<float>(-kHalf);
    hf.origin_z = static_cast<float>(-kHalf);
    hf.cell = static_cast<float>(kCell);
    hf.nx = hf.nz = n;
    std::vector<double> h(static_cast<std::size_t>(n * n));
    for (int iz = 0; iz < n; ++iz)
        for (int ix = 0; ix < n; ++ix) {
            const double fx = ix * kCell / g.relief_span_m, fz = iz * kCell / g.relief_span_m;
            const int cx = static_cast<int>(fx), cz = static_cast<int>(fz);
            const double sx = smooth(fx - cx), sz = smooth(fz - cz);
            auto at = [&](int x, int z) { return values[static_cast<std::size_t>(z * lattice + x)]; };
            const double top = at(cx, cz) + (at(cx + 1, cz) - at(cx, cz)) * sx;
            const double bottom = at(cx, cz + 1) + (at(cx + 1, cz + 1) - at(cx, cz + 1)) * sx;
            h[static_cast<std::size_t>(iz * n + ix)] = top + (bottom - top) * sz;
        }
    // The steepest grade of the bilinear surface is at a cell corner.
    double steepest = 0.0;
    for (int iz = 0; iz + 1 < n; ++iz)
        for (int ix = 0; ix + 1 < n; ++ix)
            for (int corner = 0; corner < 4; ++corner) {
                const int z = iz + (corner >> 1), x = ix + (corner & 1);
                const double gx = (h[static_cast<std::size_t>(z * n + ix + 1)] - h[static_cast<std::size_t>(z * n + ix)]) / kCell;
                const double gz = (h[static_cast<std::size_t>((iz + 1) * n + x)] - h[static_cast<std::size_t>(iz * n + x)]) / kCell;
                steepest = std::max(steepest, std::sqrt(gx * gx + gz * gz));
            }
    const double limit = tan_deg(env::kMaxSlopeDeg) * 0.995;
    const double scale = steepest > limit ? limit / steepest : 1.0;
    hf.heights.resize(h.size());
    for (std::size_t i = 0; i < h.size(); ++i) hf.heights[i] = static_cast<float>(h[i] * scale);
    g.relief_m *= scale;
    g.slope_deg = det::atan(steepest * scale) * det::kRadToDeg;
    return fmt::format("heightfield: ±{:.2f} m relief over {:.1f} m, steepest {:.1f}°", g.relief_m, g.relief_span_m, g.slope_deg);
}

// Level changes of up to max_step_height along the axis: curbs up, ledges down.
std::string make_curbs(SweepRandom& r, SweepGroundParams& g, Terrain& t) {
    const Axis a = axis_from_deg(g.axis_deg);
    g.ledges = r.integer(1, 4);
    double level = r.chance(0.3) ? r.uniform(0.05, env::kMaxStepHeightM) : 0.0;
    double u = r.uniform(0.8, 4.0);
    add_band(t, a, -env::kGroundHalfSpanM, u, level);
    std::string heights = fmt::format("{:.2f}", level);
    for (int k = 0; k < g.ledges; ++k) {
        double change = draw_hard(r, 0.03, 0.25, env::kMaxStepHeightM);
        if (r.chance(0.5) || level + change > 1.0) change = -change;
        if (level + change < 0.0) change = -change;
        level += change;
        g.largest_ledge_m = std::max(g.largest_ledge_m, std::fabs(change));
        // The last level runs on past the reach of any case (no drop at its end).
        const double length = k + 1 == g.ledges ? 2.0 * env::kGroundHalfSpanM
                                                : (r.chance(0.4) ? r.uniform(env::kMinStairTreadM, 0.6) : r.uniform(0.6, 4.0));
        add_band(t, a, u, u + length, level);
        heights += fmt::format(" → {:.2f}", level);
        u += length;
    }
    return fmt::format("curbs and ledges: levels {} m (largest change {:.3f} m)", heights, g.largest_ledge_m);
}

// Distance from the start (the origin) to a box's footprint.
double distance_to_origin(const TerrainBox& b) {
    const double dx = std::max({static_cast<double>(b.min_x), 0.0, -static_cast<double>(b.max_x)});
    const double dz = std::max({static_cast<double>(b.min_z), 0.0, -static_cast<double>(b.max_z)});
    return std::sqrt(dx * dx + dz * dz);
}

// Boxes taller than max_step_height across the path or beside it, on flat ground.
std::string make_walls(SweepRandom& r, SweepGroundParams& g, Terrain& t) {
    const Axis a = axis_from_deg(g.axis_deg);
    g.walls = r.integer(1, 3);
    std::string what;
    for (int k = 0; k < g.walls; ++k) {
        const double height = r.chance(0.3) ? r.uniform(env::kMinWallHeightM, 0.6) : r.uniform(env::kMinWallHeightM, env::kMaxWallHeightM);
        const bool across = r.chance(0.55);
        for (int attempt = 0; attempt < 32; ++attempt) {
            Terrain one;
            if (across) {
                const double u = r.uniform(1.2, 6.0), w = r.uniform(-2.5, 2.5), half = r.uniform(0.4, 5.0);
                add_box(one, a, u, u + r.uniform(0.1, 0.6), w - half, w + half, height);
            } else {
                const double side = r.chance(0.5) ? 1.0 : -1.0, face = r.uniform(0.4, 1.2), u0 = r.uniform(-3.0, 1.0);
                const double thick = r.uniform(0.1, 0.5);
                add_box(one, a, u0, u0 + r.uniform(2.0, 12.0), side * face, side * (face + thick), height);
            }
            if (distance_to_origin(one.boxes[0]) < env::kWallClearanceM) continue;
            t.boxes.push_back(one.boxes[0]);
            what += fmt::format("{}{} {:.2f} m high", what.empty() ? "" : ", ", across ? "across" : "beside", height);
            break;
        }
    }
    g.walls = static_cast<int>(t.boxes.size());
    return fmt::format("walls: {} ({})", g.walls, what);
}

}  // namespace

namespace sweep_detail {
std::string make_ground(SweepRandom& r, SweepGroundParams& g, Terrain& t, double& first_dir) {
    // Weights per ground kind, out of 100.
    static constexpr int kWeights[kSweepGroundCount] = {14, 22, 12, 12, 14, 12, 14};
    int pick = r.integer(0, 99), kind = 0;
    while (pick >= kWeights[kind]) pick -= kWeights[kind++];
    g.kind = static_cast<SweepGround>(kind);
    g.axis_deg = 90.0 * r.integer(0, 3);
    const bool along_axis = g.kind == SweepGround::stairs || g.kind == SweepGround::ramp || g.kind == SweepGround::curb ||
                            g.kind == SweepGround::wall;
    g.approach_deg = along_axis ? draw_off_axis(r) : r.uniform(-180.0, 180.0);
    first_dir = g.axis_deg + g.approach_deg;
    switch (g.kind) {
        case SweepGround::flat: return "flat";
        case SweepGround::stairs: return make_stairs(r, g, t);
        case SweepGround::ramp: return make_ramp(r, g, t);
        case SweepGround::hillside: return make_hillside(r, g, t, first_dir);
        case SweepGround::heightfield: return make_heightfield(r, g, t);
        case SweepGround::curb: return make_curbs(r, g, t);
        case SweepGround::wall: return make_walls(r, g, t);
    }
    return {};
}
}  // namespace sweep_detail

}  // namespace marionette
