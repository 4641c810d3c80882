#pragma once
// A synthetic matching source (no data files): a seven-joint body (root, two
// legs of hip, knee, ankle) whose clips walk at several speeds and curvatures,
// feet swinging in antiphase, root facing its travel. Sized by `clips` and
// `frames_per_clip`, so the same generator serves the unit tests and the
// 100,000-frame benchmark; `seed` perturbs speeds and phases deterministically.
#include <cstdint>
#include <vector>

#include "runtime/math/det_math.hpp"
#include "runtime/math/splitmix64.hpp"
#include "runtime/matching/matching_database.hpp"

namespace marionette::test {

struct MatchingFixture {
    std::vector<int> parents{-1, 0, 1, 2, 0, 4, 5};
    std::vector<quat> rotations;
    std::vector<vec3> translations;
    std::vector<std::uint8_t> contacts;
    std::vector<MatchingClipRange> clips;
    MatchingSource source() const {
        MatchingSource s;
        s.parents = parents;
        s.rotations = rotations;
        s.translations = translations;
        s.contacts = contacts;
        s.clips = clips;
        s.frame_rate = 30.0;
        s.left_foot = 3;
        s.right_foot = 6;
        return s;
    }
};

inline std::uint64_t fixture_next(std::uint64_t& s) { return splitmix64_next(s); }
inline double fixture_unit(std::uint64_t& s) { return splitmix64_unit(s); }

inline MatchingFixture make_matching_fixture(int clips, int frames_per_clip, std::uint64_t seed) {
    MatchingFixture m;
    std::uint64_t rng = seed;
    for (int c = 0; c < clips; ++c) {
        const double speed = 0.1 + 2.9 * fixture_unit(rng);             // m/s
        const double turn = (fixture_unit(rng) - 0.5) * 2.0;              // rad/s
        const double phase0 = fixture_unit(rng) * 6.283185307179586;
        const double cadence = 1.2 + speed * 0.4;                          // steps per second
        m.clips.push_back({static_cast<std::int32_t>(m.contacts.size()), frames_per_clip});
        double x = 0.0, z = 0.0, yaw = 0.0;
        for (int f = 0; f < frames_per_clip; ++f) {
            const double t = f / 30.0;
            const double phase = phase0 + 6.283185307179586 * cadence * t;
            const double swing = det::sin(phase) * (0.2 + 0.15 * speed);
            m.rotations.push_back(quat_axis_angle(vec3(0.0f, 1.0f, 0.0f), yaw));
            m.translations.push_back(vec3(static_cast<float>(x), 0.9f + 0.02f * static_cast<float>(det::cos(2.0 * phase)), static_cast<float>(z)));
            for (int leg = 0; leg < 2; ++leg) {
                const double a = leg == 0 ? swing : -swing;
                m.rotations.push_back(quat_axis_angle(vec3(1.0f, 0.0f, 0.0f), -a));
                m.translations.push_back(vec3(leg == 0 ? 0.1f : -0.1f, 0.0f, 0.0f));
                m.rotations.push_back(quat_axis_angle(vec3(1.0f, 0.0f, 0.0f), 0.3 * (1.0 + a)));
                m.translations.push_back(vec3(0.0f, -0.45f, 0.0f));
                m.rotations.push_back(quat_identity());
                m.translations.push_back(vec3(0.0f, -0.42f, 0.0f));
            }
            m.contacts.push_back(static_cast<std::uint8_t>(swing > 0.0 ? 1 : 2));
            double sn = 0.0, cs = 0.0;
            det::sin_cos(yaw, sn, cs);
            x += speed / 30.0 * sn;
            z += speed / 30.0 * cs;
            yaw += turn / 30.0;
        }
    }
    return m;
}

}  // namespace marionette::test
