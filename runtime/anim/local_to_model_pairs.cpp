// The two-joints-per-vector FK kernel (local_to_model.hpp): on x86-64 an AVX2
// function chosen at run time, two joints in the two 128-bit halves of one
// 256-bit vector, each half doing exactly what local_to_model_vector does for
// one joint (same operations, same order, no FMA: -ffp-contract=off and no
// "fma" target), so the bits are the scalar reference's. Elsewhere, and on an
// x86-64 CPU without AVX2, it runs local_to_model_vector.
//
// Why AVX2 pays on a 22-joint skeleton when four joints of a depth level per
// SSE vector did not (branch perf-fk-simd-attempt, 2x slower): no transposes.
// A joint stays in the one-joint layout (x, y, z, w in lanes), a half is one
// joint, so loading two joints is one 16-byte load plus one insert, and the
// schedule (fk_schedule.hpp) keeps a limb in one half so its parent comes from
// registers. The vector kernel runs ~77 instructions per joint, this one ~50.
#include "runtime/anim/fk_schedule.hpp"
#include "runtime/anim/local_to_model.hpp"

#include <cstdint>
#include <cstring>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define MARIONETTE_FK_PAIRS 1
#include <immintrin.h>
#endif

namespace marionette::fk {

#if defined(MARIONETTE_FK_PAIRS)

// Every function below is compiled for AVX2 (not FMA) and called only after
// the CPU check in pairs_kernel_available().
#define MARIONETTE_AVX2 __attribute__((target("avx2")))

namespace {

using f8 = float __attribute__((vector_size(32)));
using u8 = std::uint32_t __attribute__((vector_size(32)));

// The same shuffle in both halves: lanes a..d of each joint.
#define MARIONETTE_SHUFFLE8(v, a, b, c, d) __builtin_shufflevector((v), (v), a, b, c, d, 4 + (a), 4 + (b), 4 + (c), 4 + (d))

MARIONETTE_AVX2 inline f8 flip(f8 v, u8 sign_mask) {
    u8 bits;
    std::memcpy(&bits, &v, 32);
    bits ^= sign_mask;
    std::memcpy(&v, &bits, 32);
    return v;
}

constexpr std::uint32_t kSign = 0x80000000u;

// quat_mul per half: local_to_model.cpp's mul(), term for term.
MARIONETTE_AVX2 inline f8 mul(f8 a, f8 b) {
    const f8 t1 = MARIONETTE_SHUFFLE8(a, 3, 3, 3, 3) * b;
    const f8 t2 = MARIONETTE_SHUFFLE8(a, 0, 0, 0, 0) *
                  flip(MARIONETTE_SHUFFLE8(b, 3, 2, 1, 0), u8{0, kSign, 0, kSign, 0, kSign, 0, kSign});
    const f8 t3 = MARIONETTE_SHUFFLE8(a, 1, 1, 1, 1) *
                  flip(MARIONETTE_SHUFFLE8(b, 2, 3, 0, 1), u8{0, 0, kSign, kSign, 0, 0, kSign, kSign});
    const f8 t4 = MARIONETTE_SHUFFLE8(a, 2, 2, 2, 2) *
                  flip(MARIONETTE_SHUFFLE8(b, 1, 0, 3, 2), u8{kSign, 0, 0, kSign, kSign, 0, 0, kSign});
    return ((t1 + t2) + t3) + t4;
}

MARIONETTE_AVX2 inline f8 yzx(f8 v) { return MARIONETTE_SHUFFLE8(v, 1, 2, 0, 3); }
MARIONETTE_AVX2 inline f8 zxy(f8 v) { return MARIONETTE_SHUFFLE8(v, 2, 0, 1, 3); }

// quat_rotate per half: local_to_model.cpp's rotate(), term for term.
MARIONETTE_AVX2 inline f8 rotate(f8 q, f8 v) {
    const f8 q_yzx = yzx(q);
    const f8 two = {2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f};
    const f8 t_zxy = two * (q * yzx(v) - q_yzx * v);
    const f8 t = yzx(t_zxy);
    const f8 u_cross_t = yzx(q * zxy(t_zxy) - q_yzx * t);
    return (v + MARIONETTE_SHUFFLE8(q, 3, 3, 3, 3) * t) + u_cross_t;
}

MARIONETTE_AVX2 inline f8 join(__m128 low, __m128 high) {
    return f8(_mm256_insertf128_ps(_mm256_castps128_ps256(low), high, 1));
}
MARIONETTE_AVX2 inline __m128 low_half(f8 v) { return _mm256_castps256_ps128(__m256(v)); }
MARIONETTE_AVX2 inline __m128 high_half(f8 v) { return _mm256_extractf128_ps(__m256(v), 1); }

// A quat or a vec3 at a byte offset. A vec3 is read and written as an 8- and
// a 4-byte access, as in the vector kernel: never past the last joint, and
// forwarded from the store buffer when a child reads its parent.
MARIONETTE_AVX2 inline __m128 load_quat(const char* base, std::uint32_t offset) {
    return _mm_loadu_ps(reinterpret_cast<const float*>(base + offset));
}
MARIONETTE_AVX2 inline void store_quat(char* base, std::uint32_t offset, __m128 q) {
    _mm_storeu_ps(reinterpret_cast<float*>(base + offset), q);
}
MARIONETTE_AVX2 inline __m128 load_vec3(const char* base, std::uint32_t offset) {
    double xy_bits;
    std::memcpy(&xy_bits, base + offset, sizeof xy_bits);
    return _mm_movelh_ps(_mm_castpd_ps(_mm_set_sd(xy_bits)), _mm_load_ss(reinterpret_cast<const float*>(base + offset + 8)));
}
MARIONETTE_AVX2 inline void store_vec3(char* base, std::uint32_t offset, __m128 v) {
    const double xy_bits = _mm_cvtsd_f64(_mm_castps_pd(v));
    std::memcpy(base + offset, &xy_bits, sizeof xy_bits);
    _mm_store_ss(reinterpret_cast<float*>(base + offset + 8), _mm_movehl_ps(v, v));
}

MARIONETTE_AVX2 void run_pairs(const FkSchedule& schedule, const LocalPoseInput& input, const ModelPoseOutput& output) {
    const char* const local_rotations = reinterpret_cast<const char*>(input.rotations.data());
    const char* const local_translations = reinterpret_cast<const char*>(input.translations.data());
    char* const model_rotations = reinterpret_cast<char*>(output.rotations.data());
    char* const model_positions = reinterpret_cast<char*>(output.positions.data());
    const std::span<const std::uint32_t> root_rotations = schedule.root_rotation_offsets();
    const std::span<const std::uint32_t> root_positions = schedule.root_position_offsets();
    for (std::size_t r = 0; r < root_rotations.size(); ++r) {
        store_quat(model_rotations, root_rotations[r], load_quat(local_rotations, root_rotations[r]));
        store_vec3(model_positions, root_positions[r], load_vec3(local_translations, root_positions[r]));
    }
    const FkPairSlot* slot = schedule.slots().data();
    const FkPairSlot* const end = slot + schedule.slots().size();
    f8 previous_rotation{};
    f8 previous_position{};
    for (; slot != end; ++slot) {
        const FkPairSlot& s = *slot;
        const f8 local_rotation = join(load_quat(local_rotations, s.rotation_offset[0]), load_quat(local_rotations, s.rotation_offset[1]));
        const f8 local_translation =
            join(load_vec3(local_translations, s.position_offset[0]), load_vec3(local_translations, s.position_offset[1]));
        f8 parent_rotation;
        f8 parent_position;
        // Branches, not blends: a blend would wait for the load it discards.
        switch (s.chained) {
            case 3:
                parent_rotation = previous_rotation;
                parent_position = previous_position;
                break;
            case 1:
                parent_rotation = join(low_half(previous_rotation), load_quat(model_rotations, s.parent_rotation_offset[1]));
                parent_position = join(low_half(previous_position), load_vec3(model_positions, s.parent_position_offset[1]));
                break;
            case 2:
                parent_rotation = join(load_quat(model_rotations, s.parent_rotation_offset[0]), high_half(previous_rotation));
                parent_position = join(load_vec3(model_positions, s.parent_position_offset[0]), high_half(previous_position));
                break;
            default:
                parent_rotation =
                    join(load_quat(model_rotations, s.parent_rotation_offset[0]), load_quat(model_rotations, s.parent_rotation_offset[1]));
                parent_position =
                    join(load_vec3(model_positions, s.parent_position_offset[0]), load_vec3(model_positions, s.parent_position_offset[1]));
                break;
        }
        previous_rotation = mul(parent_rotation, local_rotation);
        previous_position = parent_position + rotate(parent_rotation, local_translation);
        store_quat(model_rotations, s.rotation_offset[0], low_half(previous_rotation));
        store_quat(model_rotations, s.rotation_offset[1], high_half(previous_rotation));
        store_vec3(model_positions, s.position_offset[0], low_half(previous_position));
        store_vec3(model_positions, s.position_offset[1], high_half(previous_position));
    }
}

bool cpu_has_avx2() {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2");
}

}  // namespace

bool pairs_kernel_available() {
    static const bool available = cpu_has_avx2();
    return available;
}

void local_to_model_pairs(const FkSchedule& schedule, const LocalPoseInput& input, const ModelPoseOutput& output) {
    if (pairs_kernel_available())
        run_pairs(schedule, input, output);
    else
        local_to_model_vector(schedule.parents(), input, output);
}

#else

bool pairs_kernel_available() { return false; }

void local_to_model_pairs(const FkSchedule& schedule, const LocalPoseInput& input, const ModelPoseOutput& output) {
    local_to_model_vector(schedule.parents(), input, output);
}

#endif

}  // namespace marionette::fk
