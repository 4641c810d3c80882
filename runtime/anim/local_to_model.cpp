#include "runtime/anim/local_to_model.hpp"

#include "runtime/anim/fk_schedule.hpp"

#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace marionette::fk {

void local_to_model_scalar(std::span<const int> parents, const LocalPoseInput& input, const ModelPoseOutput& output) {
    const size_t n = parents.size();
    for (size_t i = 0; i < n; ++i) {
        const int p = parents[i];
        if (p == kNoParent) {
            output.rotations[i] = input.rotations[i];
            output.positions[i] = input.translations[i];
        } else {
            const quat parent_rotation = output.rotations[static_cast<size_t>(p)];
            output.rotations[i] = quat_mul(parent_rotation, input.rotations[i]);
            output.positions[i] =
                output.positions[static_cast<size_t>(p)] + quat_rotate(parent_rotation, input.translations[i]);
        }
    }
}

// The vector kernel. Lanes 0..3 hold x, y, z, w: GLM's quat layout under
// GLM_FORCE_XYZW_ONLY (checked below), and a vec3 in lanes 0..2.
//
// Same bits as the scalar kernel, lane by lane: every lane performs the
// scalar expression's products and sums, in its order, as separate IEEE
// operations (-ffp-contract=off project-wide: no FMA). A subtraction
// `s - a*b` becomes `s + a*(-b)`: IEEE defines x - y as x + (-y) and
// a*(-b) = -(a*b) exactly, so the only possible difference is the sign or
// payload of a NaN, which IEEE leaves open and no valid pose holds.
namespace {

using f4 = float __attribute__((vector_size(16)));
using u4 = std::uint32_t __attribute__((vector_size(16)));

static_assert(sizeof(quat) == 16 && sizeof(vec3) == 12, "quat is 4 floats, vec3 is 3");

#define MARIONETTE_SHUFFLE(v, a, b, c, d) __builtin_shufflevector((v), (v), a, b, c, d)

inline f4 splat(f4 v, int lane) { return f4{v[lane], v[lane], v[lane], v[lane]}; }

inline f4 flip(f4 v, u4 sign_mask) {
    u4 bits;
    std::memcpy(&bits, &v, 16);
    bits ^= sign_mask;
    std::memcpy(&v, &bits, 16);
    return v;
}

inline f4 load_quat(const quat& q) {
    static_assert(offsetof(quat, x) == 0 && offsetof(quat, w) == 12, "GLM quat stored as x, y, z, w");
    f4 v;
    std::memcpy(&v, &q, 16);
    return v;
}

inline void store_quat(quat& q, f4 v) { std::memcpy(static_cast<void*>(&q), &v, 16); }

// A vec3 into lanes 0..2 and back, as a 64-bit and a 32-bit access (lane 3
// zero): never over-reading the last joint, and a child's load of its parent's
// position matches the parent's stores piece for piece, so the CPU forwards it
// from the store buffer (a 16-byte load over an 8- and a 4-byte store cannot).
inline f4 load_vec3(const vec3& v) {
#if defined(__SSE2__)
    // x and y as one 64-bit value through memcpy: a vec3 is only 4-byte aligned,
    // so dereferencing it as a double would be undefined (UBSan: misaligned load).
    double xy_bits;
    std::memcpy(&xy_bits, &v.x, sizeof xy_bits);
    const __m128 xy = _mm_castpd_ps(_mm_set_sd(xy_bits));
    return f4(_mm_movelh_ps(xy, _mm_load_ss(&v.z)));
#else
    const float* f = &v.x;
    return f4{f[0], f[1], f[2], 0.0f};
#endif
}

inline void store_vec3(vec3& v, f4 r) {
#if defined(__SSE2__)
    const double xy_bits = _mm_cvtsd_f64(_mm_castps_pd(__m128(r)));
    std::memcpy(&v.x, &xy_bits, sizeof xy_bits);
    _mm_store_ss(&v.z, _mm_movehl_ps(__m128(r), __m128(r)));
#else
    float* f = &v.x;
    f[0] = r[0];
    f[1] = r[1];
    f[2] = r[2];
#endif
}

constexpr std::uint32_t kSign = 0x80000000u;

// quat_mul(a, b): per lane ((a.w*b.? ± a.x*b.?) ± a.y*b.?) ± a.z*b.?, the
// scalar term order of every component.
inline f4 mul(f4 a, f4 b) {
    const f4 t1 = splat(a, 3) * b;
    const f4 t2 = splat(a, 0) * flip(MARIONETTE_SHUFFLE(b, 3, 2, 1, 0), u4{0, kSign, 0, kSign});
    const f4 t3 = splat(a, 1) * flip(MARIONETTE_SHUFFLE(b, 2, 3, 0, 1), u4{0, 0, kSign, kSign});
    const f4 t4 = splat(a, 2) * flip(MARIONETTE_SHUFFLE(b, 1, 0, 3, 2), u4{kSign, 0, 0, kSign});
    return ((t1 + t2) + t3) + t4;
}

// The cross products below use the three-shuffle form: with s = (y, z, x)
// shuffles, a*s(b) - s(a)*b holds (u×v).z, .x, .y in lanes 0, 1, 2, and
// lane 1, for one, is u.y*v.z - u.z*v.y: the scalar component's own products
// and subtraction. One more s() puts the lanes in x, y, z order.
inline f4 yzx(f4 v) { return MARIONETTE_SHUFFLE(v, 1, 2, 0, 3); }
inline f4 zxy(f4 v) { return MARIONETTE_SHUFFLE(v, 2, 0, 1, 3); }

// quat_rotate(q, v) = (v + q.w*t) + u×t, t = 2*(u×v), u = q's vector part
// (lanes 0..2 of q; lane 3 of every result is unused).
inline f4 rotate(f4 q, f4 v) {
    const f4 q_yzx = yzx(q);
    const f4 t_zxy = f4{2.0f, 2.0f, 2.0f, 2.0f} * (q * yzx(v) - q_yzx * v);  // t in lanes z, x, y
    const f4 t = yzx(t_zxy);
    const f4 u_cross_t = yzx(q * zxy(t_zxy) - q_yzx * t);  // zxy(t_zxy) is yzx(t)
    return (v + splat(q, 3) * t) + u_cross_t;
}

}  // namespace

void local_to_model_vector(std::span<const int> parents, const LocalPoseInput& input, const ModelPoseOutput& output) {
    // Raw pointers, read once: stores through the outputs could otherwise alias
    // the spans' own fields, and the compiler would reload them every joint.
    const int* const parent_of = parents.data();
    const quat* const local_rotations = input.rotations.data();
    const vec3* const local_translations = input.translations.data();
    quat* const model_rotations = output.rotations.data();
    vec3* const model_positions = output.positions.data();
    const size_t n = parents.size();
    // The previous joint's result stays in registers: in a chain (most joints'
    // parent is the joint just before) the child needs no store-to-load round trip.
    f4 previous_rotation{};
    f4 previous_position{};
    for (size_t i = 0; i < n; ++i) {
        const int p = parent_of[i];
        const f4 local_rotation = load_quat(local_rotations[i]);
        const f4 local_translation = load_vec3(local_translations[i]);
        if (p == kNoParent) {
            previous_rotation = local_rotation;
            previous_position = local_translation;
        } else {
            const size_t parent = static_cast<size_t>(p);
            const bool previous = parent + 1 == i;
            const f4 parent_rotation = previous ? previous_rotation : load_quat(model_rotations[parent]);
            const f4 parent_position = previous ? previous_position : load_vec3(model_positions[parent]);
            previous_rotation = mul(parent_rotation, local_rotation);
            previous_position = parent_position + rotate(parent_rotation, local_translation);
        }
        store_quat(model_rotations[i], previous_rotation);
        store_vec3(model_positions[i], previous_position);
    }
}

bool order_valid(std::span<const int> parents, const FkSchedule* schedule) {
    return schedule ? schedule->matches(parents) : parents_in_topological_order(parents);
}

void local_to_model(std::span<const int> parents, const FkSchedule* schedule, const LocalPoseInput& input,
                    const ModelPoseOutput& output) {
    if (schedule)
        local_to_model_pairs(*schedule, input, output);
    else
        local_to_model_vector(parents, input, output);
}

}  // namespace marionette::fk
