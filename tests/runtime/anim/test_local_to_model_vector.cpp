// The vector FK kernel (runtime/anim/local_to_model.cpp) and the pair kernel
// (local_to_model_pairs.cpp, with its FkSchedule) against the scalar reference,
// bit for bit, on generated skeletons and poses (fixed seed) across
// the envelope: 1 to 300 joints, any parent shape (chains, stars, forests,
// random trees), unit and non-unit rotations, and degenerate values (signed
// zeros, subnormals, the largest floats, infinities, NaNs), with and without
// flush-to-zero.
#include <catch2/catch.hpp>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#if defined(__x86_64__) || defined(__i386__)
#include <xmmintrin.h>
#endif

#include "runtime/anim/fk_schedule.hpp"
#include "runtime/anim/local_to_model.hpp"
#include "runtime/anim/skeleton.hpp"

using namespace marionette;

namespace {

// std::mt19937's sequence is fixed by the standard; the distributions are not,
// so every value below is made from its raw 32-bit outputs.
struct Gen {
    std::mt19937 rng;
    std::uint32_t bits() { return static_cast<std::uint32_t>(rng()); }
    size_t below(size_t n) { return static_cast<size_t>(bits() % n); }
    // Uniform-ish in [-range, range).
    float real(float range) { return (static_cast<float>(bits() >> 8) * (1.0f / 8388608.0f) - 1.0f) * range; }
    float any_bits() { return std::bit_cast<float>(bits()); }
    float special() {
        static const float values[] = {0.0f, -0.0f, std::numeric_limits<float>::denorm_min(),
                                       -std::numeric_limits<float>::denorm_min(), 1e-40f, -3e-39f,
                                       std::numeric_limits<float>::min(), std::numeric_limits<float>::max(),
                                       -std::numeric_limits<float>::max(), std::numeric_limits<float>::infinity(),
                                       -std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN(),
                                       1e30f, -1e-30f, 1.0f, -1.0f, 0.5f};
        return values[below(sizeof(values) / sizeof(values[0]))];
    }
    // One component: mostly ordinary, sometimes degenerate (kind 0 = never).
    float component(int kind, float range) {
        if (kind == 0) return real(range);
        const size_t r = below(16);
        if (r == 0) return special();
        if (r == 1 && kind == 2) return any_bits();
        return real(range);
    }
};

std::vector<int> make_parents(Gen& g, size_t n) {
    std::vector<int> parents(n);
    const size_t shape = g.below(5);
    for (size_t i = 0; i < n; ++i) {
        if (i == 0) {
            parents[i] = kNoParent;
            continue;
        }
        switch (shape) {
            case 0: parents[i] = static_cast<int>(i - 1); break;                          // one chain
            case 1: parents[i] = 0; break;                                                // a star
            case 2: parents[i] = g.below(8) == 0 ? kNoParent : static_cast<int>(g.below(i)); break;  // a forest
            case 3: parents[i] = static_cast<int>(i - 1 - g.below(i < 4 ? i : 4)); break;  // near parents
            default: parents[i] = static_cast<int>(g.below(i)); break;                     // any earlier joint
        }
    }
    return parents;
}

struct Case {
    std::vector<int> parents;
    std::vector<quat> rotations;
    std::vector<vec3> translations;
};

Case make_case(Gen& g, size_t n, int degenerate) {
    Case c;
    c.parents = make_parents(g, n);
    c.rotations.resize(n);
    c.translations.resize(n);
    for (size_t i = 0; i < n; ++i) {
        quat q = quat_wxyz(g.component(degenerate, 1.5f), g.component(degenerate, 1.5f), g.component(degenerate, 1.5f),
                           g.component(degenerate, 1.5f));
        if (degenerate == 0) q = quat_normalize(q);
        c.rotations[i] = q;
        c.translations[i] =
            vec3(g.component(degenerate, 2.0f), g.component(degenerate, 2.0f), g.component(degenerate, 2.0f));
    }
    return c;
}

bool same_float(float a, float b) {
    // IEEE leaves a NaN result's sign and payload open: x - y and x + (-y)
    // may return differently signed NaNs. Every other value must match bit for bit.
    if (std::isnan(a) && std::isnan(b)) return true;
    return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b);
}

// Runs the scalar reference and `kernel` ("vector" or "pairs"); returns "" when
// every output float matches, else where not.
std::string compare_kernels(const Case& c, const std::string& kernel, size_t& nan_results) {
    const size_t n = c.parents.size();
    // One spare entry past the skeleton: the kernels must not write it.
    std::vector<quat> sr(n + 1, quat_wxyz(7, 7, 7, 7)), vr(n + 1, quat_wxyz(7, 7, 7, 7));
    std::vector<vec3> sp(n + 1, vec3(7)), vp(n + 1, vec3(7));
    const LocalPoseInput in{c.rotations, c.translations};
    fk::local_to_model_scalar(c.parents, in, {sr, sp});
    if (kernel == "pairs") {
        const FkSchedule schedule(c.parents);
        if (!schedule.valid()) return "no schedule for these parents";
        fk::local_to_model_pairs(schedule, in, {vr, vp});
    } else {
        fk::local_to_model_vector(c.parents, in, {vr, vp});
    }
    if (!(vr[n] == quat_wxyz(7, 7, 7, 7)) || !(vp[n] == vec3(7))) return "wrote past the skeleton's last joint";
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 4; ++k) {
            if (std::isnan(sr[i][k])) ++nan_results;
            if (!same_float(sr[i][k], vr[i][k]))
                return "joint " + std::to_string(i) + " rotation[" + std::to_string(k) + "]";
            if (k < 3 && !same_float(sp[i][k], vp[i][k]))
                return "joint " + std::to_string(i) + " position[" + std::to_string(k) + "]";
        }
    return "";
}

void check_generated(std::uint32_t seed, int cases, int degenerate) {
    // The pair kernel runs as itself only on a CPU with AVX2; elsewhere it runs
    // the vector kernel, and this compares that again.
    if (!fk::pairs_kernel_available()) WARN("no AVX2 on this CPU: the pair kernel falls back to the vector kernel");
    for (const std::string kernel : {"vector", "pairs"}) {
        Gen g{std::mt19937(seed)};
        size_t nan_results = 0;
        for (int k = 0; k < cases; ++k) {
            const size_t n = k < 8 ? static_cast<size_t>(k + 1) : 1 + g.below(g.below(4) == 0 ? 300 : 70);
            const Case c = make_case(g, n, degenerate);
            const std::string where = compare_kernels(c, kernel, nan_results);
            INFO(kernel << " kernel, seed " << seed << ", case " << k << ", " << n << " joints");
            REQUIRE(where == "");
        }
        if (degenerate == 2) CHECK(nan_results > 0);  // the envelope really reached NaN outputs
    }
}

}  // namespace

TEST_CASE("FK vector and pair kernels: bit-identical to the scalar reference on generated unit poses", "[skeleton][job][fk]") {
    check_generated(20201u, 1500, 0);
}

TEST_CASE("FK vector and pair kernels: bit-identical on generated non-unit and degenerate values", "[skeleton][job][fk]") {
    check_generated(20202u, 1000, 1);
    check_generated(20203u, 1000, 2);
}

#if defined(__x86_64__) || defined(__i386__)
TEST_CASE("FK vector and pair kernels: bit-identical with flush-to-zero and denormals-are-zero", "[skeleton][job][fk]") {
    const unsigned saved = _mm_getcsr();
    _mm_setcsr(saved | 0x8040u);  // the tick's float mode (set_simulation_float_mode)
    check_generated(20204u, 500, 1);
    check_generated(20205u, 500, 2);
    _mm_setcsr(saved);
}
#endif

TEST_CASE("LocalToModelJob::run gives the scalar reference's bits, with and without a schedule", "[skeleton][job][fk]") {
    Gen g{std::mt19937(20206u)};
    for (int k = 0; k < 200; ++k) {
        const Case c = make_case(g, 1 + g.below(64), 0);
        const size_t n = c.parents.size();
        const FkSchedule schedule(c.parents);
        std::vector<quat> sr(n), jr(n), pr(n);
        std::vector<vec3> sp(n), jp(n), pp(n);
        fk::local_to_model_scalar(c.parents, {c.rotations, c.translations}, {sr, sp});
        REQUIRE(LocalToModelJob{c.parents, {c.rotations, c.translations}, {jr, jp}}.run());
        REQUIRE(LocalToModelJob{c.parents, {c.rotations, c.translations}, {pr, pp}, &schedule}.run());
        INFO("case " << k);
        REQUIRE(std::memcmp(sr.data(), jr.data(), n * sizeof(quat)) == 0);
        REQUIRE(std::memcmp(sp.data(), jp.data(), n * sizeof(vec3)) == 0);
        REQUIRE(std::memcmp(sr.data(), pr.data(), n * sizeof(quat)) == 0);
        REQUIRE(std::memcmp(sp.data(), pp.data(), n * sizeof(vec3)) == 0);
    }
}

TEST_CASE("parents_in_topological_order: the one-comparison form at the int extremes", "[skeleton][job]") {
    const int lo = std::numeric_limits<int>::min();
    const int hi = std::numeric_limits<int>::max();
    CHECK(parents_in_topological_order(std::vector<int>{}));
    CHECK(parents_in_topological_order(std::vector<int>{kNoParent, 0, 1, kNoParent, 0, 4}));
    CHECK_FALSE(parents_in_topological_order(std::vector<int>{0}));
    CHECK_FALSE(parents_in_topological_order(std::vector<int>{kNoParent, lo}));
    CHECK_FALSE(parents_in_topological_order(std::vector<int>{kNoParent, hi}));
    CHECK_FALSE(parents_in_topological_order(std::vector<int>{kNoParent, -2}));
    CHECK_FALSE(parents_in_topological_order(std::vector<int>{kNoParent, 0, 2}));
    CHECK_FALSE(parents_in_topological_order(std::vector<int>{kNoParent, 0, 1, 1, 5}));
}
