// gait-eval --sweep's generator and runner (app/eval/gait_sweep.*): the random
// numbers are splitmix64, a seed gives the same cases every time (and case i is
// the same whatever N is), every case lies inside the envelope of docs/gait.md
// and reaches its edges, and the files --out writes load back to the same
// program and terrain and reproduce the same metrics.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

#include "app/config/config.hpp"
#include "app/config/program_source.hpp"
#include "app/config/terrain_file.hpp"
#include "app/eval/gait_sweep.hpp"
#include "app/io/files.hpp"
#include "runtime/math/det_math.hpp"

using namespace marionette;
namespace env = sweep_envelope;

namespace {

const SimConfig& shipped_config() {
    static const AppConfig app = default_config();
    return app.sim;
}

// The world (x, z) a stick angle that is a multiple of 90° walks toward.
void axis_direction(double axis_deg, double& dx, double& dz) {
    static constexpr double kDir[4][2] = {{1, 0}, {0, -1}, {-1, 0}, {0, 1}};
    const int q = static_cast<int>(std::lround(axis_deg / 90.0)) & 3;
    dx = kDir[q][0];
    dz = kDir[q][1];
}

// The surface along the feature's axis through the start, every 5 mm.
std::vector<double> profile(const SweepCase& c, double from_u, double to_u) {
    double dx = 0.0, dz = 0.0;
    axis_direction(c.ground.axis_deg, dx, dz);
    std::vector<double> h;
    for (double u = from_u; u <= to_u; u += 0.005)
        h.push_back(query_ground(c.terrain, static_cast<float>(u * dx), static_cast<float>(u * dz)).height);
    return h;
}

struct Steps {
    int count = 0;
    double largest = 0.0;           // largest height change between neighbouring samples
    double shortest_inner_run = 1e9;  // shortest level stretch between two steps (m)
};

Steps steps_along(const std::vector<double>& h) {
    Steps s;
    int last_step = -1;
    for (std::size_t i = 1; i < h.size(); ++i) {
        const double change = std::fabs(h[i] - h[i - 1]);
        s.largest = std::max(s.largest, change);
        if (change < 0.01) continue;
        ++s.count;
        if (last_step >= 0) s.shortest_inner_run = std::min(s.shortest_inner_run, (static_cast<int>(i) - last_step) * 0.005);
        last_step = static_cast<int>(i);
    }
    return s;
}

double slope_deg(float grade_x, float grade_z) {
    return det::atan(std::sqrt(static_cast<double>(grade_x) * grade_x + static_cast<double>(grade_z) * grade_z)) * det::kRadToDeg;
}

}  // namespace

TEST_CASE("gait sweep: the random numbers are splitmix64, floats from 0 up to 1, integers in their range", "[gait_sweep]") {
    SweepRandom zero(0);
    CHECK(zero.next() == 0xE220A8397B1DCDAFull);  // splitmix64's published first output for seed 0
    CHECK(zero.next() == 0x6E789E6AA1B965F4ull);
    SweepRandom r(7);
    CHECK(r.next() == 0x63CBE1E459320DD7ull);
    bool low = false, high = false;
    for (int i = 0; i < 10000; ++i) {
        const double u = r.uniform();
        REQUIRE(u >= 0.0);
        REQUIRE(u < 1.0);
        const int k = r.integer(-3, 3);
        REQUIRE(k >= -3);
        REQUIRE(k <= 3);
        low = low || k == -3;
        high = high || k == 3;
    }
    CHECK(low);
    CHECK(high);
}

TEST_CASE("gait sweep: a seed gives the same cases every time, and case i whatever N is", "[gait_sweep]") {
    const SimConfig& config = shipped_config();
    for (int i = 0; i < 40; ++i) {
        const SweepCase a = generate_sweep_case(7, i, config);
        const SweepCase b = generate_sweep_case(7, i, config);
        CHECK(a.id == b.id);
        CHECK(a.program_text == b.program_text);
        CHECK(a.terrain == b.terrain);
        CHECK(a.description == b.description);
        const SweepCase other = generate_sweep_case(8, i, config);
        CHECK(other.program_text != a.program_text);
    }
    CHECK(generate_sweep_case(7, 3, config).id == "7-0003");
    // Running 3 cases and running 5 give the same first 3.
    const SweepSummary three = run_gait_sweep(config, 11, 3, {});
    const SweepSummary five = run_gait_sweep(config, 11, 5, {});
    CHECK(three.cases == 3);
    CHECK(five.cases == 5);
    for (const SweepFailure& f : three.failures) {
        const auto same = std::find_if(five.failures.begin(), five.failures.end(), [&](const SweepFailure& g) { return g.case_id == f.case_id; });
        REQUIRE(same != five.failures.end());
        CHECK(same->metrics.final_hash == f.metrics.final_hash);
    }
    // A pinned fingerprint of seed 7's first 30 cases (program text and terrain
    // file): the generator uses integer random numbers, IEEE arithmetic and
    // det_math only, so this holds on every compiler, library and CPU. A
    // deliberate change to the generator changes it: update the number then.
    std::uint64_t fingerprint = 1469598103934665603ull;  // FNV-1a
    for (int i = 0; i < 30; ++i) {
        const SweepCase c = generate_sweep_case(7, i, config);
        for (const char ch : c.program_text + sweep_terrain_file_text(c))
            fingerprint = (fingerprint ^ static_cast<unsigned char>(ch)) * 1099511628211ull;
    }
    CHECK(fingerprint == 0xB128F27E56E90409ull);
}

TEST_CASE("gait sweep: every generated case lies inside the envelope", "[gait_sweep]") {
    const SimConfig& config = shipped_config();
    for (int i = 0; i < 400; ++i) {
        const SweepCase c = generate_sweep_case(3, i, config);
        INFO(c.id << ": " << c.description);
        // The program: 6-12 s, its text is what runs.
        const double seconds = c.program.duration_s();
        CHECK(seconds >= env::kMinCaseS - 1e-9);
        CHECK(seconds <= env::kMaxCaseS + 1e-9);
        CHECK(parse_stick_program(c.program_text, "again").segments.size() == c.program.segments.size());
        const SweepGroundParams& g = c.ground;
        CHECK(c.speed_checked == (g.kind != SweepGround::wall));
        switch (g.kind) {
            case SweepGround::flat: CHECK(c.terrain == Terrain{}); break;
            case SweepGround::stairs: {
                CHECK(g.rise_m <= env::kMaxStairRiseM);
                CHECK(g.tread_m >= env::kMinStairTreadM);
                CHECK(std::fabs(g.approach_deg) <= env::kMaxOffAxisDeg);
                // Measured on the built ground: every riser at most 22 cm, every
                // tread (and landing) at least 25 cm deep, as many risers as drawn.
                const Steps s = steps_along(profile(c, -10.0, 70.0));
                CHECK(s.largest <= env::kMaxStairRiseM + 1e-4);
                CHECK(s.shortest_inner_run >= env::kMinStairTreadM - 0.006);
                CHECK(s.count == g.flights * g.risers_per_flight * (g.start_on_top ? 1 : 2));
                break;
            }
            case SweepGround::ramp:
            case SweepGround::hillside: {
                CHECK(g.slope_deg <= env::kMaxSlopeDeg);
                for (const TerrainSlope& s : c.terrain.slopes) CHECK(slope_deg(s.grade_x, s.grade_z) <= env::kMaxSlopeDeg + 1e-4);
                if (g.kind == SweepGround::ramp) {
                    CHECK(std::fabs(g.approach_deg) <= env::kMaxOffAxisDeg);
                    CHECK(steps_along(profile(c, -10.0, 70.0)).largest < 0.005);  // no step anywhere: a ramp, not a ledge
                }
                break;
            }
            case SweepGround::heightfield: {
                const Heightfield& hf = c.terrain.heightfield;
                CHECK(g.relief_span_m >= env::kMinReliefSpanM);
                for (const float h : hf.heights) REQUIRE(std::fabs(h) <= env::kMaxReliefM + 1e-6);
                double steepest = 0.0;
                for (int z = 0; z + 1 < hf.nz; ++z)
                    for (int x = 0; x + 1 < hf.nx; ++x) {
                        const auto at = [&](int xi, int zi) { return static_cast<double>(hf.heights[static_cast<std::size_t>(zi * hf.nx + xi)]); };
                        steepest = std::max({steepest, std::fabs(at(x + 1, z) - at(x, z)) / hf.cell, std::fabs(at(x, z + 1) - at(x, z)) / hf.cell});
                    }
                CHECK(det::atan(steepest) * det::kRadToDeg <= env::kMaxSlopeDeg + 1e-3);
                break;
            }
            case SweepGround::curb: {
                CHECK(g.largest_ledge_m <= env::kMaxStepHeightM);
                CHECK(std::fabs(g.approach_deg) <= env::kMaxOffAxisDeg);
                const Steps s = steps_along(profile(c, -10.0, 70.0));
                CHECK(s.largest <= env::kMaxStepHeightM + 1e-4);
                CHECK(s.shortest_inner_run >= env::kMinStairTreadM - 0.006);
                break;
            }
            case SweepGround::wall: {
                CHECK(std::fabs(g.approach_deg) <= env::kMaxOffAxisDeg);
                CHECK(g.walls >= 1);
                CHECK(static_cast<int>(c.terrain.boxes.size()) == g.walls);
                for (const TerrainBox& b : c.terrain.boxes) {
                    CHECK(b.top > env::kMaxStepHeightM);
                    CHECK(b.top <= env::kMaxWallHeightM);
                    // The puppet starts clear of every wall.
                    const double dx = std::max({static_cast<double>(b.min_x), 0.0, -static_cast<double>(b.max_x)});
                    const double dz = std::max({static_cast<double>(b.min_z), 0.0, -static_cast<double>(b.max_z)});
                    CHECK(std::sqrt(dx * dx + dz * dz) >= env::kWallClearanceM);
                }
                break;
            }
        }
    }
}

TEST_CASE("gait sweep: the cases reach the edges of the envelope, every kind of ground and stick move", "[gait_sweep]") {
    const SimConfig& config = shipped_config();
    std::set<SweepGround> kinds;
    std::set<std::string> moves;
    double steepest_slope = 0.0, highest_rise = 0.0, shortest_tread = 1.0, widest_approach = 0.0, highest_ledge = 0.0;
    bool down_first = false, up_first = false, eight_risers = false, low_wall = false;
    for (int i = 0; i < 400; ++i) {
        const SweepCase c = generate_sweep_case(5, i, config);
        const SweepGroundParams& g = c.ground;
        kinds.insert(g.kind);
        for (const char* move : {"step turn", "ramp turn", "reversal", "circle", "stop", "pulses", "noise", "near dead zone", "press"})
            if (c.description.find(move) != std::string::npos) moves.insert(move);
        if (g.kind == SweepGround::ramp || g.kind == SweepGround::hillside) steepest_slope = std::max(steepest_slope, g.slope_deg);
        if (g.kind == SweepGround::stairs) {
            highest_rise = std::max(highest_rise, g.rise_m);
            shortest_tread = std::min(shortest_tread, g.tread_m);
            (g.start_on_top ? down_first : up_first) = true;
            eight_risers = eight_risers || g.risers_per_flight == 8;
        }
        if (g.kind != SweepGround::flat && g.kind != SweepGround::heightfield && g.kind != SweepGround::hillside)
            widest_approach = std::max(widest_approach, std::fabs(g.approach_deg));
        if (g.kind == SweepGround::curb) highest_ledge = std::max(highest_ledge, g.largest_ledge_m);
        if (g.kind == SweepGround::wall)
            for (const TerrainBox& b : c.terrain.boxes) low_wall = low_wall || b.top < 0.5f;
    }
    CHECK(kinds.size() == static_cast<std::size_t>(kSweepGroundCount));
    CHECK(moves.size() == 9);
    CHECK(steepest_slope > 29.0);
    CHECK(highest_rise > 0.215);
    CHECK(shortest_tread < 0.26);
    CHECK(widest_approach > 57.0);
    CHECK(highest_ledge > 0.33);
    CHECK(down_first);
    CHECK(up_first);
    CHECK(eight_risers);
    CHECK(low_wall);
}

TEST_CASE("gait sweep: --out files load back with the plain loaders and reproduce the same metrics", "[gait_sweep]") {
    const SimConfig& config = shipped_config();
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "marionette_test_gait_sweep";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    // One case of every kind of ground.
    std::set<SweepGround> done;
    for (int i = 0; i < 200 && done.size() < static_cast<std::size_t>(kSweepGroundCount); ++i) {
        const SweepCase c = generate_sweep_case(9, i, config);
        if (!done.insert(c.ground.kind).second) continue;
        INFO(c.id << ": " << c.description);
        const std::string prog = (dir / (c.id + ".prog")).string(), toml = (dir / (c.id + ".toml")).string();
        write_text_file(prog, sweep_program_file_text(c));
        write_text_file(toml, sweep_terrain_file_text(c));
        SimConfig replay = config;
        replay.terrain = load_terrain(toml);
        CHECK(replay.terrain == c.terrain);
        const StickProgram program = load_program(prog);
        REQUIRE(program.segments.size() == c.program.segments.size());
        const SweepCaseResult swept = evaluate_sweep_case(c, config);
        const GaitMetrics again = evaluate_gait(replay, program);
        CHECK(again.final_hash == swept.metrics.final_hash);
        CHECK(again.ticks == swept.metrics.ticks);
        for (const SweepMetric& m : kSweepMetrics) CHECK(again.*m.value == swept.metrics.*m.value);
    }
    CHECK(done.size() == static_cast<std::size_t>(kSweepGroundCount));
    // run_gait_sweep writes both files for every failing case and nothing else.
    const std::filesystem::path out = dir / "out";
    const SweepSummary s = run_gait_sweep(config, 9, 12, out.string());
    std::set<std::string> written;
    for (const auto& entry : std::filesystem::directory_iterator(out)) written.insert(entry.path().filename().string());
    std::set<std::string> expected;
    for (const SweepFailure& f : s.failures) {
        expected.insert(f.case_id + ".prog");
        expected.insert(f.case_id + ".toml");
    }
    CHECK(written == expected);
    CHECK(s.passed + static_cast<int>(s.failures.size()) == 12);
    std::filesystem::remove_all(dir);
}

// Kept regressions (issue 13): sweep cases that once broke a foot limit, each
// held to the limits its cause was fixed for. A failing case is kept here, its
// cause fixed; the envelope is never narrowed.
namespace {
struct SweepRegression {
    std::uint64_t seed;
    int index;
};
// The limits a kept case is held to.
struct Held {
    bool skate = false;
    bool penetration = false;
    bool obstacle = false;
    double joint_speed_deg_s = 0.0;  // > 0: the joint speed is held under this
    bool every_limit = false;        // the sweep's own verdict: no limit broken
};
void check_sweep_regressions(std::initializer_list<SweepRegression> cases, Held held) {
    const SimConfig& config = shipped_config();
    for (const SweepRegression& r : cases) {
        const SweepCase c = generate_sweep_case(r.seed, r.index, config);
        const SweepCaseResult result = evaluate_sweep_case(c, config);
        INFO(c.id << ": " << c.description << ": " << result.problem);
        const GaitMetrics& m = result.metrics;
        if (held.skate) CHECK(m.foot_skate_mm < kMaxFootSkateMm);
        if (held.penetration) CHECK(m.penetration_mm < kMaxPenetrationMm);
        if (held.obstacle) CHECK(m.obstacle_penetration_mm < kMaxObstaclePenetrationMm);
        if (held.joint_speed_deg_s > 0.0) CHECK(m.max_joint_speed_deg_s < held.joint_speed_deg_s);
        if (held.every_limit) CHECK(result.problem.empty());
    }
}
}  // namespace

// A swing whose landing spot the root left behind (a turn in place or a sharp
// turn starting late in the swing, past the ordinary re-aim window) re-aims at
// any progress: before, the pelvis sank to reach the old spot (to 0.33 m on flat
// ground) and the stance foot slid up to 545 mm when it stood up again.
TEST_CASE("gait sweep regressions: a stranded swing re-aims, no stance foot slides", "[gait_sweep]") {
    check_sweep_regressions({{7, 12}, {7, 47}, {7, 81}, {7, 162}, {7, 231}, {7, 239}, {7, 398}, {7, 416}, {7, 493},
                             {7, 592}, {7, 638}, {7, 699}, {7, 826}, {7, 954}, {1, 208}, {1, 254}, {1, 282}},
                            {.skate = true});
}

// The pelvis sinks in time for a swing's landing (issue 13, branch gaitsweep):
// held to at most 0.9 m/s, it met a swing's soft reach limit late and the hard
// limit dropped it by up to 3 cm a tick just before touchdown, spinning a shin;
// and the root's stall on the planted foot (walking) is in the prediction of
// where the hip will be. Each of these broke the joint-speed limit on main
// (°/s): hillside 7-0409 1912, 1-0257 2994; stairs 7-0488 3248, 7-0644 3312;
// curbs 7-0226 2895, 1-0100 2577.
TEST_CASE("gait sweep regressions: the pelvis sinks in time for a landing, no shin spins", "[gait_sweep]") {
    check_sweep_regressions({{7, 409}, {1, 257}, {7, 488}, {7, 644}, {7, 226}, {1, 100}},
                            {.skate = true, .penetration = true, .joint_speed_deg_s = kMaxJointSpeedDegS});
}

// A foot turns and swings in the time its turn and travel need (issue 13,
// branch gait3): a stop or closing swing takes at least its turn at 300 °/s on
// average (held to 0.15–0.3 s, a foot turned 100–175° and the foot joint passed
// 1500 °/s: 1-0071 1589, 7-0012 1502, 7-0289 1561, 7-0877 2307, 7-0144 1555),
// and a swing lifted or re-aimed late in its phase takes at least its travel at
// 4 m/s (it had the cycle's last hundredths of a second for up to 1 m: 1-0205
// 1638, 1-0238 1705, 1-0155 1921, 7-0009 1594, 7-0942 1769, 7-0588 1923,
// 1-0125 1568 °/s).
TEST_CASE("gait sweep regressions: a foot's turn and travel get their time, no foot or shin spins", "[gait_sweep]") {
    check_sweep_regressions({{1, 71}, {7, 12}, {7, 289}, {7, 877}, {7, 144}, {1, 205}, {1, 238}, {1, 155}, {7, 9},
                             {7, 942}, {7, 588}, {1, 125}},
                            {.skate = true, .penetration = true, .joint_speed_deg_s = kMaxJointSpeedDegS});
}

// A swing path ramps toward a high key (branch gaitstairs): 1-0121 put a toe
// 5.4 mm into a tread before.
TEST_CASE("gait sweep regressions: the swing path clears the next tread", "[gait_sweep]") {
    check_sweep_regressions({{1, 121}}, {.penetration = true});
}

// Running up 21 cm / 28 cm stairs at 54° off their axis, the swing's ankle
// descended between path keys while its toe was inside the next riser (113 mm
// on main, 153 mm on branch gait3); a swing aimed for the time it takes (branch
// gait4) lands clear: 0.0009 mm.
TEST_CASE("gait sweep regressions: 7-0080, no toe inside a riser running up stairs at an angle", "[gait_sweep]") {
    check_sweep_regressions({{7, 80}}, {.penetration = true});
}

// A swing held to its travel at 4 m/s that outlasts its phase is aimed for its
// own time, and a re-aim after its phase wrapped keeps its lift phase (branch
// gait4): every case of `--sweep 300 --seed 2` that failed on main and passes
// now meets every limit (2-0122: 5,352 °/s on main).
TEST_CASE("gait sweep regressions: seed 2's cases fixed by the gait3 and gait4 changes meet every limit", "[gait_sweep]") {
    check_sweep_regressions({{2, 4}, {2, 13}, {2, 30}, {2, 56}, {2, 63}, {2, 87}, {2, 97}, {2, 122}, {2, 169},
                             {2, 171}, {2, 184}, {2, 211}, {2, 242}, {2, 263}},
                            {.every_limit = true});
}

// A stranded swing is judged by the spot it would really be re-aimed at (the
// one aimed for the time the swing will take, branch gait9). Judged by the
// phase's spot, a swing on a turning path re-aimed every tick to about the spot
// it already had, its progress held at 0 for up to 140 ticks while the pelvis
// sank to reach it, and the lifting foot was pulled into the tread behind it:
// 2-0052 (walking down 11.5 cm stairs, the stick circling) 103.7 mm and
// 3,681 °/s, 7-0655 (up 22 cm / 28 cm stairs) 15.7 mm and 2,812 °/s on main
// fd8f33e. The same loop broke the joint-speed limit in the other cases (°/s on
// main): 1-0062 2976, 1-0091 1817, 1-0265 2693, 2-0227 3161, 7-0220 2708,
// 7-0495 1782, 7-0512 3696, 7-0564 3147, 7-0680 2032, 7-0684 2247, 7-0797 2607,
// 7-0918 3146, 7-0950 2909, 7-0956 1557.
TEST_CASE("gait sweep regressions: a stranded swing does not re-aim every tick and no foot enters a tread", "[gait_sweep]") {
    check_sweep_regressions({{2, 52}, {7, 655}}, {.penetration = true, .every_limit = true});
    check_sweep_regressions({{1, 62}, {1, 91}, {1, 265}, {2, 227}, {7, 220}, {7, 495}, {7, 512}, {7, 564}, {7, 680},
                             {7, 684}, {7, 797}, {7, 918}, {7, 950}, {7, 956}},
                            {.every_limit = true});
}

// 7-0285 (19 cm / 33 cm stairs, walking down; 1,415 °/s on main) reached
// 18,398 °/s (thigh_r) with the path prediction asking ground_speed() (branch
// gait3's change 3, dropped on branch gait4): the left foot stepped three
// treads down, the right was left on the landing above and its thigh flipped.
TEST_CASE("gait sweep regressions: 7-0285, no thigh flips walking down a flight", "[gait_sweep]") {
    check_sweep_regressions({{7, 285}}, {.every_limit = true});
}

// A swing's clearance floor counts its toe tip swung out sideways, as it counts
// the ankle (the swing moves 1–3 cm sideways): a foot lifting beside a riser
// its toes pointed at, 1 cm from the edge, swung them into it. Penetration on
// main 545ca01 (mm): 13-0408 145, 13-0002 148, 5-0356 132, 14-0073 36,
// 13-0116 14, 11-0484 10.6 (six of the 6,000 cases of seeds 3–6 and 8–15).
TEST_CASE("gait sweep regressions: no toe swings into a riser beside it", "[gait_sweep]") {
    check_sweep_regressions({{13, 408}, {13, 2}, {5, 356}, {14, 73}, {13, 116}, {11, 484}},
                            {.skate = true, .penetration = true});
}

// The stand-off holds for every way the root moves (steered, pulled by the
// stance reach, settling between the feet when idle), and no stop or turning
// step lands on a wall's top or within 6 cm of its face. Before (main 545ca01),
// beside a 2.16 m wall the idle root settled 5 cm from its face and the right
// forearm went 82 mm into it (3-0001); 13-0001 12.4 mm, 14-0131 10.0 mm.
TEST_CASE("gait sweep regressions: the body and feet stay out of walls beside the path", "[gait_sweep]") {
    check_sweep_regressions({{3, 1}, {13, 1}, {14, 131}},
                            {.skate = true, .penetration = true, .obstacle = true});
}

// A step rises or drops at most 0.52 of the leg (0.45 m) from the planted
// foot's ground (gait10): a stride of three or four risers folded the higher
// leg to the hip. Joint speed before (main 57debb2, °/s): 4-0125 7,773,
// 11-0479 3,827, 3-0183 3,140, 10-0487 2,519, 9-0131 2,416, 4-0289 2,162,
// 13-0274 2,140 (stairs), 5-0185 2,060 (curbs) — 27 of the 6,000 cases of
// seeds 3–6 and 8–15 fixed, 3 broken (1,528–1,704 °/s).
// 10-0487 broke again with gait12 (2,206 °/s, thigh_r): a run turning on the
// stairs re-aimed one foot four risers above the other while the other, in the
// same flight, re-aimed down, and in a flight the limit did not apply. Since
// gait13 a step in a flight rises or drops at most that much from the other
// foot's landing (docs/gait.md, gait13): 1,358 °/s.
TEST_CASE("gait sweep regressions: no stride of three or four risers, no folded leg", "[gait_sweep]") {
    check_sweep_regressions({{4, 125}, {11, 479}, {3, 183}, {10, 487}, {9, 131}, {4, 289}, {13, 274}, {5, 185}},
                            {.every_limit = true});
}

// A swinging foot left more than 0.6 m behind its hip lowers the pelvis no
// further than 0.35 of the leg above a planted ankle (gait10): a swing stranded
// a metre back and below pulled the pelvis down to the planted ankle and that
// thigh flipped (main 6994af1: 10-0441, 27.5° hillside, 8,639 °/s; 13-0316,
// 21° ramp, 7,999 °/s). Both stayed over the limit (1,673 and 1,535 °/s: the
// stranded swing itself) until gait12 (within every limit since: the re-aim
// test below); this holds them to the flip's absence whatever else changes.
TEST_CASE("gait sweep regressions: a swing left far behind does not fold the planted leg", "[gait_sweep]") {
    check_sweep_regressions({{10, 441}, {13, 316}},
                            {.skate = true, .penetration = true, .joint_speed_deg_s = 1800.0});
}

// The pelvis follows a swing within bounds (gait11): a far swing lowers it no
// faster than it may sink (in a run's flight no ankle was planted to stop it:
// 6-0372, 3,593 °/s); it sinks toward a landing swing's soft limit at no more
// than 3 m/s (that limit jumped 4 cm in a tick when the other foot lifted:
// 5-0439, 2,685 °/s); it rises at up to 1.5 m/s to keep a swinging ankle 0.3 of
// the leg below its hip (a swing two risers up passed 7 cm from its hip: 3-0256,
// 3,314 °/s, now 1,989: held to the fold's absence). 17 of the 6,000 cases of
// seeds 3–6 and 8–15 fixed (main 8554f56 → gait11), 2 broken (1,518 and
// 1,568 °/s).
TEST_CASE("gait sweep regressions: the pelvis sinks and rises within bounds for a swing", "[gait_sweep]") {
    check_sweep_regressions({{5, 439}, {10, 182}, {10, 342}, {11, 147}, {12, 105}, {12, 199}, {12, 329}, {13, 101},
                             {14, 129}, {14, 311}, {14, 425}, {4, 385}, {4, 411}, {5, 68}, {8, 256}, {9, 115}},
                            {.every_limit = true});
    // 6-0372 (3,593 °/s before gait11) was 42 °/s over with gait12 and 13 (a
    // shin at a landing) and within every limit again since gait14.
    check_sweep_regressions({{6, 372}}, {.every_limit = true});
    check_sweep_regressions({{3, 256}}, {.skate = true, .penetration = true, .joint_speed_deg_s = 2100.0});
}

// A re-aimed swing carries the foot's velocity into its new path (gait12): the
// new path starts from rest, so the foot stopped dead in one tick and the shin
// or foot spun. 37 of the 6,000 cases of seeds 3–6 and 8–15 fixed (main
// 45c9f43 → gait12), 15 broken; the worst fixed, °/s before: 14-0468 4,254
// (25° hillside), 9-0400 1,839, 8-0491 1,783, 10-0441 1,779, 12-0186 1,739,
// 13-0316 1,732, 12-0383 1,686 (flat), 4-0210 1,671, 11-0324 1,668; and of
// seeds 1, 2 and 7: 7-0456 3,800, 2-0115 1,747, 1-0134 1,559, 1-0039 1,529,
// 7-0284 1,543, 7-0239 1,520, 7-0699 1,513.
TEST_CASE("gait sweep regressions: a re-aimed swing carries the foot's velocity, no foot stops dead", "[gait_sweep]") {
    check_sweep_regressions({{9, 400}, {8, 491}, {10, 441}, {12, 186}, {13, 316}, {12, 383}, {4, 210}, {11, 324},
                             {2, 115}, {1, 134}, {1, 39}, {7, 284}, {7, 239}, {7, 699}},
                            {.every_limit = true});
    // 14-0468 (25° hillside, 4,254 °/s before gait12) passed with gait12, was
    // 9 °/s over from gait13 to gait17 and meets every limit again since gait18.
    // 7-0456 (stairs down, 3,800 °/s before gait12) passed until gait16, failed
    // for another cause through gait17 (docs/gait.md) and meets every limit
    // since gait18.
    check_sweep_regressions({{14, 468}, {7, 456}}, {.every_limit = true});
}

// The swinging foot turns evenly in time between the progress where its step
// fraction passes 0.1 and where it passes 0.9 (gait16): turning with the step
// fraction, it turned 3-4 times its mean rate mid-swing and the foot joint
// spun. Each broke the joint-speed limit on 19f8aa7 (°/s, foot joints): curbs
// 7-0613 1562, 7-0163 1510, 2-0001 1505, 1-0255 1612, 14-0479 1929, 14-0009
// 1660, 3-0064 1584; ramps 1-0281 1583, 2-0186 1537; stairs 9-0345 1752,
// 13-0326 1665, 4-0026 1625; hillside 14-0014 1611.
TEST_CASE("gait sweep regressions: a swinging foot turns evenly in time, no foot joint spins", "[gait_sweep]") {
    check_sweep_regressions({{7, 613}, {7, 163}, {2, 1}, {1, 255}, {14, 479}, {14, 9}, {3, 64}, {1, 281}, {2, 186}, {9, 345},
                             {13, 326}, {4, 26}, {14, 14}},
                            {.every_limit = true});
}

// A built swing takes its whole path, climbs and drops included, at no more
// than 5 m/s on average (gait17): held to its horizontal travel at 4 m/s only,
// a step beside a riser lifted 0.22 m straight up at 9 m/s and the shin spun
// where the path turned across. Each broke the joint-speed limit on c477054
// (°/s): stairs 7-0961 1930, 13-0475 1803, 6-0460 1549, 6-0139 1543, 4-0397
// 1539, 14-0476 1536; curbs 7-0977 1527, 11-0295 1710, 3-0216 1508; hillsides
// 5-0498 1584, 6-0278 1540, 11-0084 1534; ramp 6-0103 1519.
TEST_CASE("gait sweep regressions: a swing takes its climb and drop at a bounded speed, no shin spins", "[gait_sweep]") {
    check_sweep_regressions({{7, 961}, {13, 475}, {6, 460}, {6, 139}, {4, 397}, {14, 476}, {7, 977}, {11, 295}, {3, 216},
                             {5, 498}, {6, 278}, {11, 84}},
                            {.every_limit = true});
    // 6-0103 (ramp, 1,519 °/s before gait17) is 3 °/s over since gait20 (a
    // knee flexing at a landing): a known failure below, held here to that.
    check_sweep_regressions({{6, 103}}, {.skate = true, .penetration = true, .joint_speed_deg_s = 1550.0});
}

// A fast walk's duty shrinks so its swings keep within 0.9 of the 4 m/s mean
// swing speed (gait18): at walk_duty 0.58 a walk above 1.68 m/s asked more of
// its swings than they may take, they landed late, and the planted foot
// behind held the root. Each broke a limit on 9b092b3: speed error (%) ramps
// 7-0551 2.18, 9-0166 2.23, 12-0303 2.51, 12-0345 2.94; stairs 3-0253 2.59,
// 8-0344 2.78, 9-0093 3.36, 9-0186 2.03, 12-0004 6.57, 13-0119 2.01, 14-0190
// 9.38; joint speed (°/s) 3-0013 1511 (hillside), 3-0256 1970, 6-0154 1560
// (stairs), 4-0208 1644, 12-0235 1869 (curbs), 9-0255 2577 (wall).
TEST_CASE("gait sweep regressions: a fast walk's swings keep their speed, the root is not held", "[gait_sweep]") {
    check_sweep_regressions({{7, 551}, {9, 166}, {12, 303}, {12, 345}, {3, 253}, {8, 344}, {9, 93}, {9, 186}, {12, 4},
                             {13, 119}, {14, 190}, {3, 13}, {3, 256}, {6, 154}, {4, 208}, {12, 235}, {9, 255}},
                            {.every_limit = true});
}

// A planned foot turns the way the root will (gait19): aimed at the predicted
// heading by the shortest way, a foot behind a root spun round by a circling
// stick turned against the spin and was turned back at the next re-aim. Each
// broke the joint-speed limit on gait18 (°/s): 7-0163 1697 (curbs), 5-0010
// 2013, 6-0056 1997 (stairs).
TEST_CASE("gait sweep regressions: a foot turns the way the root turns, not back", "[gait_sweep]") {
    check_sweep_regressions({{7, 163}, {5, 10}, {6, 56}}, {.every_limit = true});
}

// A swing takes at least 0.14 s (gait20; 0.12 s before): a turn in place
// re-aiming a swing late in its phase took a foot 0.31 m across and 0.39 m down
// a hillside in 0.12 s. Each broke the joint-speed limit on gait19 (°/s):
// 14-0014 1577, 13-0049 1520, 14-0171 1509 (hillsides), 13-0124 1842, 3-0447
// 1561 (flat), 13-0195 1534, 3-0072 1509 (heightfields), 10-0152 1529, 10-0453
// 1512 (stairs), 9-0149 1508 (curbs).
TEST_CASE("gait sweep regressions: a late swing gets 0.14 s, no shin spins", "[gait_sweep]") {
    check_sweep_regressions({{14, 14}, {13, 49}, {14, 171}, {13, 124}, {3, 447}, {13, 195}, {3, 72}, {10, 152}, {10, 453},
                             {9, 149}},
                            {.every_limit = true});
}

// A foot still on its stop swing when stepping resumed re-aims when the root
// leaves its spot behind (gait21): left to land, it hovered while the root sped
// off and the pelvis sank to reach it. Each broke the joint-speed limit on
// gait20 (°/s): walls 7-0755 2633, 4-0449 1693, 12-0159 1860, 12-0225 1976,
// 13-0001 2040; stairs 8-0425 1784, 13-0211 2159; ramp 13-0231 1514.
TEST_CASE("gait sweep regressions: a stop swing the root runs away from re-aims, no leg spins", "[gait_sweep]") {
    check_sweep_regressions({{7, 755}, {4, 449}, {12, 159}, {12, 225}, {13, 1}, {8, 425}, {13, 211}, {13, 231}},
                            {.every_limit = true});
}

// A short step turning beside a wall turns over the first or the second half of
// the step when its mid-step turn would sweep the toes through the wall's
// corner (gait22): 2-0085 lifted the foot 1.1 m over a 1.09 m wall instead
// (7,465 °/s, the knee 23.8 mm inside the wall). 7-0196 is a running stride
// beside a 0.53 m wall, which keeps its path over the wall: turning over its
// second half instead put a toe tip 449 mm below the wall's top.
TEST_CASE("gait sweep regressions: a short step turning beside a wall keeps its toes out of it", "[gait_sweep]") {
    check_sweep_regressions({{2, 85}, {7, 196}}, {.every_limit = true});
}

// The pelvis rises ahead of a swing path's highest point, not only once the
// ankle is there (gait23): climbing two risers in one step, the pelvis rose
// too late and the ankle passed 0.18 m from its hip at 4.5 m/s. Each broke
// the joint-speed limit on gait22 (°/s): stairs 7-0154 1564 (foot), 9-0263
// 1548 (foot), 10-0428 1571 (shin).
TEST_CASE("gait sweep regressions: the pelvis rises ahead of a two-riser step, no foot whips past the hip", "[gait_sweep]") {
    check_sweep_regressions({{7, 154}, {9, 263}, {10, 428}}, {.every_limit = true});
}

// A stop swing slows while its hip–ankle line would turn faster than 12 rad/s
// (gait24): a foot stranded 0.07 m below its hip on a tread stopped 1 m across
// and 0.55 m down at 4.3 m/s past the hip (stairs 7-0283, foot 1,575 °/s on
// gait23).
TEST_CASE("gait sweep regressions: a stop swing from beside the hip slows, no shin whips", "[gait_sweep]") {
    check_sweep_regressions({{7, 283}}, {.every_limit = true});
}

// gait-eval's speed expectation starts from the speed the puppet reports when a
// hold's window opens, not from the command there: crossing a landing at a run
// toward a flight, the grade read ahead had already lowered the command and the
// puppet was still braking to it when the window opened. Measured against a
// follower that started at the command, the pelvis was "too fast": stairs
// 9-0039 2.84 %, 10-0298 2.18 %. No change to the gait.
TEST_CASE("gait sweep regressions: the speed expectation starts from the puppet's speed, not the command", "[gait_sweep]") {
    check_sweep_regressions({{9, 39}, {10, 298}}, {.every_limit = true});
}

// Known failures, kept so they stay found: cases a change fixed once and a
// later change broke again (docs/gait.md). They may fail; the tests above hold
// them to bounds they must not pass.
TEST_CASE("gait sweep known failure: 6-0103 (gait17), broken again by gait20", "[gait_sweep][!mayfail]") {
    check_sweep_regressions({{6, 103}}, {.every_limit = true});
}
