// Database clips of other skeletons for `clip fill`: retargeted onto the filled
// clip's skeleton through the humanoid chains (graph_builder/fill_retarget.*,
// docs/fill.md).
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>

#include "graph_builder/clip_fill.hpp"
#include "graph_builder/fill_retarget.hpp"
#include "retarget/humanoid.hpp"
#include "retarget/pose_space.hpp"
#include "runtime/anim/two_bone_ik.hpp"
#include "runtime/errors/import_error.hpp"
#include "runtime/formats/asf_amc.hpp"
#include "runtime/formats/bvh.hpp"
#include "runtime/math/det_math.hpp"
#include "tests/test_support.hpp"

using namespace marionette;
using namespace marionette::offline;

namespace {

std::uint64_t splitmix(std::uint64_t& s) {
    std::uint64_t z = (s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}
double uniform(std::uint64_t& s, double lo, double hi) {
    return lo + (hi - lo) * static_cast<double>(splitmix(s) >> 11) / 9007199254740992.0;
}

// The whole clip turned about +Y by `yaw` and scaled by `k` (units and facing of
// another capture): offsets and root path turned and scaled, every local
// rotation conjugated by the turn, so the world motion is the same motion turned.
Clip turned_and_scaled(Clip c, double yaw, double k) {
    const quat q = quat_axis_angle(vec3(0, 1, 0), yaw), qi = quat_conjugate(q);
    const float kf = static_cast<float>(k);
    for (vec3& o : c.skeleton.rest_offsets) o = kf * quat_rotate(q, o);
    for (vec3& o : c.skeleton.end_site_offsets) o = kf * quat_rotate(q, o);
    for (quat& r : c.rotations) r = quat_normalize(quat_mul(quat_mul(q, r), qi));
    for (vec3& t : c.translations) t = kf * quat_rotate(q, t);
    return c;
}

std::string import_message(const auto& f) {
    try {
        f();
    } catch (const ImportError& e) {
        return e.what();
    }
    return "(no error)";
}

// Mean over frames and roles of cos(target bone, source bone), both in their
// own world frames turned to face the same way (the source's rest facing onto the
// target's), for the roles whose bones have a direction.
double mean_bone_agreement(const Clip& src, const Clip& out, const Clip& target) {
    const retarget::HumanoidChains hs = retarget::detect_humanoid(src, "src", nullptr);
    const retarget::HumanoidChains ht = retarget::detect_humanoid(target, "target", nullptr);
    const retarget::ModelFrames ms = retarget::model_frames(src), mo = retarget::model_frames(out);
    const auto facing = [](const retarget::ModelFrames& m, const retarget::HumanoidChains& h) {
        const vec3 l = m.position(0, h.joint[retarget::role::thigh_l]) - m.position(0, h.joint[retarget::role::thigh_r]);
        return glm::normalize(glm::cross(vec3(l.x, 0.0f, l.z), vec3(0, 1, 0)));
    };
    // Per frame the facing of both: compare directions in each clip's own hip frame.
    double sum = 0.0;
    int count = 0;
    for (int f = 0; f < src.frame_count; f += 7) {
        const vec3 fs = facing(ms, hs), fo = facing(mo, ht);
        const quat turn = quat_from_to(glm::normalize(vec3(fs.x, 0, fs.z)), glm::normalize(vec3(fo.x, 0, fo.z)));
        for (int r : {retarget::role::thigh_l, retarget::role::shin_l, retarget::role::thigh_r, retarget::role::shin_r,
                      retarget::role::upperarm_l, retarget::role::forearm_l, retarget::role::upperarm_r, retarget::role::forearm_r}) {
            const auto pt = [&](const retarget::ModelFrames& m, retarget::SourcePoint p) {
                return lerp(m.position(f, p.a), m.position(f, p.b), p.t);
            };
            const size_t u = static_cast<size_t>(r);
            const vec3 ds = glm::normalize(quat_rotate(turn, pt(ms, hs.to[u]) - pt(ms, hs.from[u])));
            const vec3 dout = glm::normalize(pt(mo, ht.to[u]) - pt(mo, ht.from[u]));
            sum += glm::dot(ds, dout);
            ++count;
        }
    }
    return count ? sum / count : 0.0;
}

}  // namespace

TEST_CASE("fill retarget: on the same skeleton the legs' and arms' rotations come through exactly", "[fill]") {
    const std::string dir = test::mocap_dir();
    if (dir.empty()) return;  // skipped without the shared data (fails under CI=true)
    const std::string asf = dir + "/cmu_amc_16/16.asf";
    const Clip src = load_asf_amc_files(asf, dir + "/cmu_amc_16/16_15.amc");
    const Clip target = load_asf_amc_files(asf, dir + "/cmu_amc_16/16_11.amc");
    const Clip out = retarget_fill_clip(src, "16_15.amc", target, "16_11.amc");
    REQUIRE(out.frame_count == src.frame_count);
    REQUIRE(check_fill_skeleton(target.skeleton, out.skeleton).ok());
    double worst = 0.0;
    for (const char* name : {"lfemur", "ltibia", "lfoot", "rfemur", "rtibia", "rfoot", "lhumerus", "lradius", "rhumerus", "rradius"}) {
        const int j = src.skeleton.find(name);
        REQUIRE(j >= 0);
        for (int f = 0; f < src.frame_count; ++f) {
            const size_t i = static_cast<size_t>(f * src.joint_count() + j);
            worst = std::max(worst, 1.0 - static_cast<double>(std::abs(glm::dot(src.rotations[i], out.rotations[i]))));
        }
    }
    CHECK(worst < 1e-5);
}

TEST_CASE("fill retarget: generated turns and scales of another skeleton's clip give the same motion", "[fill]") {
    const std::string dir = test::mocap_dir();
    if (dir.empty()) return;
    const Clip target = load_asf_amc_files(dir + "/cmu_amc_16/16.asf", dir + "/cmu_amc_16/16_11.amc");
    const Clip src = load_bvh_file(dir + "/cmu_bvh_131/131_01.bvh");
    const Clip ref = retarget_fill_clip(src, "131_01.bvh", target, "16_11.amc");
    REQUIRE(check_fill_skeleton(target.skeleton, ref.skeleton).ok());
    // The bones point where the source's do.
    CHECK(mean_bone_agreement(src, ref, target) > 0.97);
    // Envelope: any facing, units from a tenth to ten times (mm to m captures).
    std::uint64_t seed = 15;
    for (int k = 0; k < 12; ++k) {
        const double yaw = uniform(seed, -3.14159, 3.14159), scale = std::exp(uniform(seed, std::log(0.1), std::log(10.0)));
        INFO("case " << k << ": yaw " << yaw << " rad, scale " << scale);
        const Clip out = retarget_fill_clip(turned_and_scaled(src, yaw, scale), "131_01.bvh", target, "16_11.amc");
        double rot = 0.0, pos = 0.0;
        for (size_t i = 0; i < out.rotations.size(); ++i) {
            rot = std::max(rot, 1.0 - static_cast<double>(std::abs(glm::dot(out.rotations[i], ref.rotations[i]))));
            pos = std::max(pos, static_cast<double>(glm::length(out.translations[i] - ref.translations[i])));
        }
        CHECK(rot < 1e-4);
        CHECK(pos < 0.05);  // file units of the target (ASF: 0.45 in ≈ 1.1 cm)
    }
}

TEST_CASE("fill retarget: a retargeted database loads and fills, an unrelated skeleton is refused", "[fill]") {
    const std::string dir = test::mocap_dir();
    if (dir.empty()) return;
    const std::string asf = dir + "/cmu_amc_16/16.asf";
    Clip input = load_asf_amc_files(asf, dir + "/cmu_amc_16/16_15.amc");
    const Clip truth = input;
    std::vector<Clip> db;
    for (const char* f : {"131_01.bvh", "131_02.bvh", "131_03.bvh"})
        db.push_back(retarget_fill_clip(load_bvh_file(dir + "/cmu_bvh_131/" + f), f, input, "16_15.amc"));
    const FillDatabase prepared = prepare_fill_database(std::move(db));
    FillGap g;
    g.hidden = resolve_hidden_joints(input.skeleton, "arms", "--hide");
    g.first = 120;
    g.last = 179;
    FillOptions fo;
    const FillMatch m = fill_gap(input, g, &prepared, fo);
    CHECK(m.found);
    CHECK(m.clip >= 0);
    // Visible joints untouched, hidden ones changed and finite.
    int changed = 0;
    for (int f = 0; f < input.frame_count; ++f)
        for (int j = 0; j < input.joint_count(); ++j) {
            const size_t i = static_cast<size_t>(f * input.joint_count() + j);
            const bool hidden = g.hidden[static_cast<size_t>(j)] && f >= g.first && f <= g.last;
            if (!hidden) REQUIRE(std::memcmp(&input.rotations[i], &truth.rotations[i], sizeof(quat)) == 0);
            else changed += input.rotations[i] != truth.rotations[i];
            REQUIRE(std::isfinite(input.rotations[i].w));
        }
    CHECK(changed > 100);

    // A skeleton with no humanoid in it: refused, naming the file and why.
    Clip chain;
    chain.name = "chain";
    chain.skeleton.joint_names = {"a", "b", "c"};
    chain.skeleton.parents = {kNoParent, 0, 1};
    chain.skeleton.rest_offsets = {vec3(0), vec3(0, 10, 0), vec3(0, 10, 0)};
    chain.skeleton.end_site_parents = {2};
    chain.skeleton.end_site_offsets = {vec3(0, 10, 0)};
    chain.frame_count = 3;
    chain.rotations.assign(9, quat_identity());
    chain.translations.assign(9, vec3(0));
    chain.animated_translation = {true, false, false};
    CHECK_THAT(import_message([&] { (void)retarget_fill_clip(chain, "chain.bvh", input, "16_15.amc"); }),
               Catch::Contains("chain.bvh") && Catch::Contains("cannot be retargeted onto it") &&
                   Catch::Contains("no humanoid found"));
}
