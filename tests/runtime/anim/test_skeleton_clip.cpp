#include <catch2/catch.hpp>

#include "runtime/anim/clip.hpp"
#include "runtime/gait/puppet.hpp"
#include "tests/runtime/anim/chain_skeleton.hpp"

using namespace marionette;

using test::chain;

TEST_CASE("validate_skeleton names what is wrong", "[skeleton]") {
    Skeleton s = chain();
    s.joint_names[2] = "mid";
    CHECK_THAT(validate_skeleton(s).problem(), Catch::Contains("duplicate joint name 'mid'"));
    s = chain();
    s.parents[1] = 2;
    CHECK_THAT(validate_skeleton(s).problem(), Catch::Contains("not an earlier joint"));
}

TEST_CASE("clip sampling interpolates and resampling keeps the motion", "[clip]") {
    Clip clip;
    clip.skeleton = chain();
    clip.frame_rate = 10.0;
    clip.frame_count = 3;
    clip.animated_translation = {true, false, false};
    for (int f = 0; f < 3; ++f)
        for (int j = 0; j < 3; ++j) {
            clip.rotations.push_back(j == 1 ? quat_axis_angle(vec3(0, 0, 1), 0.5 * f) : quat_identity());
            clip.translations.push_back(j == 0 ? vec3(f * 1.0f, 0, 0) : clip.skeleton.rest_offsets[static_cast<size_t>(j)]);
        }
    REQUIRE(validate_clip(clip).ok());
    std::vector<quat> r(3);
    std::vector<vec3> t(3);
    sample_clip(clip, 0.05, ClipWrap::clamp, r, t);  // halfway between frames 0 and 1
    CHECK(t[0].x == Approx(0.5));
    CHECK(quat_angle_between(r[1], quat_axis_angle(vec3(0, 0, 1), 0.25)) < 1e-6);
    sample_clip(clip, 99.0, ClipWrap::clamp, r, t);
    CHECK(t[0].x == Approx(2.0));
    sample_clip(clip, 0.25, ClipWrap::loop, r, t);  // 0.25 s wraps to 0.05 s in a 0.2 s loop
    CHECK(t[0].x == Approx(0.5));

    const Clip fine = resample_clip(clip, 40.0);
    CHECK(fine.frame_count == 9);
    CHECK(fine.frame_rate == 40.0);
    CHECK(fine.frame_translations(8)[0].x == Approx(2.0));
    CHECK(fine.frame_translations(1)[0].x == Approx(0.25));
    CHECK(validate_clip(fine).ok());
}

TEST_CASE("the default puppet has 22 joints and stands on the ground", "[puppet]") {
    const GaitConfig config;
    const Skeleton s = make_puppet_skeleton(config);
    REQUIRE(validate_skeleton(s).ok());
    CHECK(s.joint_count() == kPuppetJointCount);
    CHECK(s.joint_count() == 22);
    const Clip idle = make_idle_clip(s, config);
    const Clip walk = make_walk_clip(s, config);
    REQUIRE(validate_clip(idle).ok());
    REQUIRE(validate_clip(walk).ok());
    std::vector<quat> mr(22);
    std::vector<vec3> mp(22);
    REQUIRE(LocalToModelJob{s.parents,
                            {std::span<const quat>(idle.frame_rotations(0), 22),
                             std::span<const vec3>(idle.frame_translations(0), 22)},
                            {mr, mp}}
                .run());
    // Rest pose: the toes' joint lies at sole height (0) within a millimetre.
    CHECK(mp[kToeL].y == Approx(0.0).margin(0.01));
    CHECK(mp[kHead].y > 1.5f);
    CHECK(mp[kThighL].x > 0.0f);  // left is +X
    // Looping clips end where they start.
    CHECK(quat_angle_between(walk.frame_rotations(0)[kThighL], walk.frame_rotations(walk.frame_count - 1)[kThighL]) < 1e-5);
    CHECK(hash_clip(walk) != hash_clip(idle));
    CHECK(hash_clip(walk) == hash_clip(make_walk_clip(s, config)));
}
