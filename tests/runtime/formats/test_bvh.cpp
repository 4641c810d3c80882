#include <catch2/catch.hpp>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "runtime/formats/bvh.hpp"
#include "tests/seeded_random.hpp"
#include "tests/test_support.hpp"

using namespace marionette;

namespace {

// Round-trip tolerances the exporter promises.
constexpr double kRoundTripDegrees = 1e-4;
constexpr double kRoundTripUnits = 1e-5;
// Forward kinematics against the independent reference.
constexpr double kFkTolerance = 1e-3;

std::string fixture(const std::string& name) {
    return test::read_text_file(test::source_path("tests/data/bvh/" + name));
}

std::vector<std::string> shared_bvh_files() {
    std::vector<std::string> files;
    const std::string dir = test::mocap_dir();
    if (dir.empty()) return files;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(dir))
        if (entry.is_regular_file() && entry.path().extension() == ".bvh") files.push_back(entry.path().string());
    std::sort(files.begin(), files.end());
    return files;
}

// Model-space joint positions of one frame through the runtime's FK job.
std::vector<vec3> model_positions(const Clip& clip, int frame) {
    const auto n = static_cast<size_t>(clip.joint_count());
    std::vector<quat> mr(n);
    std::vector<vec3> mp(n);
    const LocalToModelJob job{clip.skeleton.parents,
                              {std::span<const quat>(clip.frame_rotations(frame), n),
                               std::span<const vec3>(clip.frame_translations(frame), n)},
                              {mr, mp}};
    REQUIRE(job.validate());
    REQUIRE(job.run());
    return mp;
}

// ----------------------------------------------------------------------------
// An independent BVH reader for the FK check: whitespace tokens through
// istringstream, numbers through operator>>, joint transforms as double 4×4
// matrices composed from glm::translate and one glm::rotate per channel. It
// shares nothing with runtime/formats/bvh.cpp but the written conventions.
struct RefJoint {
    std::string name;
    int parent = -1;
    glm::dvec3 offset{0.0};
    std::vector<std::string> channels;
};

struct RefClip {
    std::vector<RefJoint> joints;
    std::vector<std::vector<double>> frames;
};

RefClip reference_read(const std::string& text) {
    std::istringstream in(text);
    RefClip clip;
    std::vector<int> open;  // joint index per '{', -1 for End Site
    int pending = -1;
    std::string word;
    while (in >> word && word != "MOTION") {
        if (word == "ROOT" || word == "JOINT") {
            RefJoint j;
            in >> j.name;
            j.parent = open.empty() ? -1 : open.back();
            clip.joints.push_back(j);
            pending = static_cast<int>(clip.joints.size()) - 1;
        } else if (word == "End") {
            in >> word;  // Site
            pending = -1;
        } else if (word == "{") {
            open.push_back(pending);
        } else if (word == "}") {
            open.pop_back();
        } else if (word == "OFFSET") {
            glm::dvec3 o;
            in >> o.x >> o.y >> o.z;
            if (open.back() >= 0) clip.joints[static_cast<size_t>(open.back())].offset = o;
        } else if (word == "CHANNELS") {
            int n = 0;
            in >> n;
            auto& ch = clip.joints[static_cast<size_t>(open.back())].channels;
            ch.resize(static_cast<size_t>(n));
            for (auto& c : ch) in >> c;
        }
    }
    int frames = 0;
    double frame_time = 0.0;
    in >> word >> frames >> word >> word >> frame_time;  // Frames: N Frame Time: t
    size_t channels = 0;
    for (const auto& j : clip.joints) channels += j.channels.size();
    clip.frames.assign(static_cast<size_t>(frames), std::vector<double>(channels));
    for (auto& f : clip.frames)
        for (double& v : f) in >> v;
    return clip;
}

std::vector<glm::dvec3> reference_positions(const RefClip& clip, int frame) {
    std::vector<glm::dmat4> global(clip.joints.size());
    std::vector<glm::dvec3> out(clip.joints.size());
    size_t k = 0;
    for (size_t j = 0; j < clip.joints.size(); ++j) {
        const RefJoint& joint = clip.joints[j];
        glm::dvec3 t = joint.offset;
        glm::dmat4 rotation(1.0);
        for (const std::string& c : joint.channels) {
            const double v = clip.frames[static_cast<size_t>(frame)][k++];
            const int axis = c[0] - 'X';
            if (c.find("position") != std::string::npos) {
                t[axis] = v;
            } else {
                glm::dvec3 unit(0.0);
                unit[axis] = 1.0;
                rotation = glm::rotate(rotation, glm::radians(v), unit);  // rotation · R(channel)
            }
        }
        const glm::dmat4 local = glm::translate(glm::dmat4(1.0), t) * rotation;
        global[j] = joint.parent < 0 ? local : global[static_cast<size_t>(joint.parent)] * local;
        out[j] = glm::dvec3(global[j][3]);
    }
    return out;
}

// ----------------------------------------------------------------------------

// Every prefix, mutation or garbage buffer must parse or throw ImportError;
// anything else (another exception, a crash under the sanitizers) fails.
bool parses_or_import_error(const std::string& text) {
    try {
        const Clip clip = import_bvh(text, "fuzz.bvh");
        REQUIRE(validate_clip(clip).ok());
        return true;
    } catch (const ImportError& e) {
        REQUIRE(e.file() == "fuzz.bvh");
        REQUIRE(e.line() >= 1);
        REQUIRE(!e.message().empty());
        return false;
    }
}

using SplitMix = test::SeededRandom;

void require_same_skeleton(const Skeleton& a, const Skeleton& b) {
    REQUIRE(a.joint_names == b.joint_names);
    REQUIRE(a.parents == b.parents);
    for (size_t j = 0; j < a.rest_offsets.size(); ++j) REQUIRE(a.rest_offsets[j] == b.rest_offsets[j]);
    REQUIRE(a.end_site_parents == b.end_site_parents);
    for (size_t e = 0; e < a.end_site_offsets.size(); ++e) REQUIRE(a.end_site_offsets[e] == b.end_site_offsets[e]);
}

// Largest rotation difference (degrees) and translation difference over all
// frames, with joints matched by name.
void require_same_motion(const Clip& a, const Clip& b) {
    REQUIRE(a.frame_count == b.frame_count);
    REQUIRE(a.joint_count() == b.joint_count());
    REQUIRE(b.frame_rate == Approx(a.frame_rate).epsilon(1e-12));
    double worst_degrees = 0.0;
    double worst_units = 0.0;
    for (int j = 0; j < a.joint_count(); ++j) {
        const int k = b.skeleton.find(a.skeleton.joint_names[static_cast<size_t>(j)]);
        REQUIRE(k >= 0);
        for (int f = 0; f < a.frame_count; ++f) {
            const double deg = quat_angle_between(a.frame_rotations(f)[j], b.frame_rotations(f)[k]) * det::kRadToDeg;
            const vec3 d = a.frame_translations(f)[j] - b.frame_translations(f)[k];
            worst_degrees = std::max(worst_degrees, deg);
            worst_units = std::max({worst_units, static_cast<double>(std::abs(d.x)), static_cast<double>(std::abs(d.y)),
                                    static_cast<double>(std::abs(d.z))});
        }
    }
    INFO("worst rotation difference " << worst_degrees << " degrees, translation " << worst_units);
    CHECK(worst_degrees < kRoundTripDegrees);
    CHECK(worst_units < kRoundTripUnits);
}

}  // namespace

// ============================================================================

TEST_CASE("BVH channels compose in the listed order", "[bvh]") {
    const Clip clip = import_bvh(fixture("channel_order.bvh"), "tests/data/bvh/channel_order.bvh");
    REQUIRE(validate_clip(clip).ok());
    CHECK(clip.name == "channel_order");
    REQUIRE(clip.joint_count() == 3);
    CHECK(clip.skeleton.joint_names == std::vector<std::string>{"root", "arm", "hand"});
    CHECK(clip.skeleton.parents == std::vector<int>{kNoParent, 0, 1});
    CHECK(clip.frame_count == 5);
    CHECK(clip.frame_rate == 2.0);
    REQUIRE(clip.skeleton.end_site_parents == std::vector<int>{2});
    CHECK(clip.skeleton.end_site_offsets[0] == vec3(0, 0, 1));

    // Worked out by hand with Rz90:(x,y,z)→(−y,x,z), Rx90:(x,y,z)→(x,−z,y),
    // Ry90:(x,y,z)→(z,y,−x), applying the rightmost factor first:
    //  f1 root ZXY (90,90,0): Rz·Rx·(0,1,0) = (0,0,1); Rz·Rx·(1,2,0) = (0,1,2)
    //  f2 arm XZY (90,90,0): Rx·Rz·(1,5,0) = (−5,0,1)
    //  f3 root ZXY (0,90,90): Rx·Ry·(0,1,0) = (0,0,1); Rx·Ry·(1,2,0) = (0,1,2)
    //  f4 arm Y 90: Ry·(1,2,0) = (0,2,−1)
    // The opposite composition order gives a different answer in f1, f2 and f3.
    const vec3 expected[5][3] = {
        {{0, 0, 0}, {0, 1, 0}, {1, 3, 0}},
        {{10, 20, 30}, {10, 20, 31}, {10, 21, 33}},
        {{0, 0, 0}, {0, 1, 0}, {-5, 1, 1}},
        {{0, 0, 0}, {0, 0, 1}, {0, 1, 3}},
        {{0, 0, 0}, {0, 1, 0}, {0, 3, -1}},
    };
    for (int f = 0; f < 5; ++f) {
        const std::vector<vec3> p = model_positions(clip, f);
        for (int j = 0; j < 3; ++j) {
            INFO("frame " << f << " joint " << j);
            CHECK(p[static_cast<size_t>(j)].x == Approx(expected[f][j].x).margin(1e-5));
            CHECK(p[static_cast<size_t>(j)].y == Approx(expected[f][j].y).margin(1e-5));
            CHECK(p[static_cast<size_t>(j)].z == Approx(expected[f][j].z).margin(1e-5));
        }
    }
    // Rotations are unit quaternions.
    for (const quat& q : clip.rotations) CHECK(quat_dot(q, q) == Approx(1.0f).margin(1e-6));
}

TEST_CASE("BVH position channels replace the offset, on any joint", "[bvh]") {
    const Clip clip = import_bvh(fixture("channel_order.bvh"), "channel_order.bvh");
    CHECK(clip.animated_translation == std::vector<bool>{true, false, true});
    // The hand's only position channel is Y: X and Z stay at the OFFSET (1, 2, 0).
    CHECK(clip.frame_translations(0)[2] == vec3(1, 2, 0));
    CHECK(clip.frame_translations(2)[2] == vec3(1, 5, 0));
    // The arm has no position channel: its OFFSET every frame.
    for (int f = 0; f < clip.frame_count; ++f) CHECK(clip.frame_translations(f)[1] == vec3(0, 1, 0));
    CHECK(clip.frame_translations(1)[0] == vec3(10, 20, 30));

    // Position and rotation channels interleaved, on a child joint.
    const std::string text =
        "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 1 Zrotation\nJOINT b\n{\nOFFSET 7 8 9\n"
        "CHANNELS 4 Zposition Xrotation Xposition Yrotation\nEnd Site\n{\nOFFSET 0 0 0\n}\n}\n}\n"
        "MOTION\nFrames: 1\nFrame Time: 0.1\n90 -3 90 4 0\n";
    const Clip mixed = import_bvh(text, "mixed");
    CHECK(mixed.animated_translation == std::vector<bool>{false, true});
    CHECK(mixed.frame_translations(0)[0] == vec3(0, 0, 0));
    CHECK(mixed.frame_translations(0)[1] == vec3(4, 8, -3));
    // Root Z 90 turns b's translation (4, 8, −3) into (−8, 4, −3).
    const std::vector<vec3> p = model_positions(mixed, 0);
    CHECK(p[1].x == Approx(-8).margin(1e-5));
    CHECK(p[1].y == Approx(4).margin(1e-5));
    CHECK(p[1].z == Approx(-3).margin(1e-5));
    CHECK(quat_angle_between(mixed.frame_rotations(0)[1], quat_axis_angle(vec3(1, 0, 0), det::kHalfPi)) < 1e-6);
}

TEST_CASE("BVH formatting variants: spacing, numbers, names, several roots", "[bvh]") {
    const Clip clip = import_bvh(fixture("formats.bvh"), "formats.bvh");
    REQUIRE(validate_clip(clip).ok());
    CHECK(clip.skeleton.joint_names == std::vector<std::string>{"mixamorig:Hips", "mixamorig:Spine", "prop|handle.001"});
    // A second ROOT is another joint without a parent.
    CHECK(clip.skeleton.parents == std::vector<int>{kNoParent, 0, kNoParent});
    CHECK(clip.skeleton.rest_offsets[0] == vec3(10.0f, -0.5f, 2.0f));
    CHECK(clip.skeleton.rest_offsets[1] == vec3(0.25f, 0.001f, 0.0f));
    CHECK(clip.skeleton.end_site_parents == std::vector<int>{1});
    CHECK(clip.frame_count == 2);
    CHECK(clip.frame_rate == Approx(1.0 / 0.0083333));
    CHECK(clip.animated_translation == std::vector<bool>{true, false, true});
    CHECK(clip.frame_translations(0)[0] == vec3(1.5f, -0.5f, 10.0f));
    CHECK(clip.frame_translations(1)[0] == vec3(-0.1f, 3.0f, 0.0f));
    CHECK(clip.frame_translations(0)[2] == vec3(0.0f, 0.0f, 4.0f));
    CHECK(clip.frame_translations(1)[2] == vec3(0.0f, 0.0f, -2.0f));
    CHECK(quat_angle_between(clip.frame_rotations(0)[2], quat_axis_angle(vec3(0, 1, 0), det::kHalfPi)) < 1e-6);
    CHECK(quat_angle_between(clip.frame_rotations(1)[2], quat_axis_angle(vec3(0, 1, 0), -det::kHalfPi)) < 1e-6);
    // A joint with CHANNELS 0 keeps the identity and its offset.
    CHECK(clip.frame_rotations(1)[1] == quat_identity());
    CHECK(clip.frame_translations(1)[1] == clip.skeleton.rest_offsets[1]);
}

TEST_CASE("BVH Frames and Frame Time line variants, byte order mark", "[bvh]") {
    const std::string hierarchy = "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n}\nMOTION\n";
    const std::vector<std::pair<std::string, double>> headers = {
        {"Frames: 2\nFrame Time: 0.5\n", 2.0},
        {"Frames:2\nFrame Time:0.5\n", 2.0},
        {"Frames:\t2\nFrame Time:\t.5\n", 2.0},
        {"Frames 2\nFrame Time 5e-1\n", 2.0},
        {"FRAMES : 2\nframe time : +0.25\n", 4.0},
        {"  Frames:   2  \n\n  FrameTime:  1.0E-1  \n", 10.0},
        {"Frames: +2\nFrame  Time: .0083333\n", 1.0 / 0.0083333},
    };
    for (const auto& [header, rate] : headers) {
        INFO(header);
        const Clip clip = import_bvh(hierarchy + header + "10\n-10\n", "variants");
        CHECK(clip.frame_count == 2);
        CHECK(clip.frame_rate == Approx(rate).epsilon(1e-12));
    }
    const Clip bom = import_bvh("\xEF\xBB\xBF" + hierarchy + "Frames: 1\nFrame Time: 1\n0\n", "bom");
    CHECK(bom.skeleton.joint_names[0] == "a");
}

TEST_CASE("BVH line ends: LF, CRLF, CR and mixed read alike", "[bvh]") {
    const std::string lf = fixture("channel_order.bvh");
    auto convert = [&](int mode) {
        std::string out;
        int n = 0;
        for (char c : lf) {
            if (c != '\n') {
                out += c;
                continue;
            }
            const int kind = mode == 3 ? (n++ % 3) : mode;
            out += kind == 0 ? "\n" : (kind == 1 ? "\r\n" : "\r");
        }
        return out;
    };
    const Clip reference = import_bvh(lf, "lf");
    for (int mode = 1; mode <= 3; ++mode) {
        INFO("mode " << mode);
        const Clip clip = import_bvh(convert(mode), "converted");
        REQUIRE(clip.frame_count == reference.frame_count);
        CHECK(clip.skeleton.joint_names == reference.skeleton.joint_names);
        for (size_t i = 0; i < clip.rotations.size(); ++i) {
            CHECK(clip.rotations[i] == reference.rotations[i]);
            CHECK(clip.translations[i] == reference.translations[i]);
        }
    }
    // Line numbers in errors count CRLF and CR line ends once each.
    std::string bad = lf;
    bad.replace(bad.find("90 90 0 5"), 9, "90 90 x 5");
    std::string crlf;
    for (char c : bad) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
    for (const std::string& text : {bad, crlf}) {
        try {
            import_bvh(text, "bad.bvh");
            FAIL("no error");
        } catch (const ImportError& e) {
            CHECK(e.line() == 26);
            CHECK_THAT(e.message(), Catch::Contains("found 'x'"));
        }
    }
}

TEST_CASE("BVH import of the shared mocap files", "[bvh][mocap]") {
    const std::string dir = test::mocap_dir();
    if (dir.empty()) return;
    struct Expected {
        const char* file;
        int frames;
        int joints;
        double rate;
        const char* root;
    };
    const Expected expected[] = {
        {"cmu_bvh_131/131_01.bvh", 994, 31, 120.0, "Hips"},
        {"cmu_bvh_131/131_02.bvh", 1247, 31, 120.0, "Hips"},
        {"cmu_bvh_131/131_03.bvh", 1102, 31, 120.0, "Hips"},
        {"edge/mixamo_55_joints.bvh", 69, 55, 30.0, "mixamorig:Hips"},
    };
    for (const Expected& e : expected) {
        const std::string path = dir + "/" + e.file;
        INFO(path);
        const Clip clip = load_bvh_file(path);
        REQUIRE(validate_clip(clip).ok());
        CHECK(clip.name == std::filesystem::path(path).stem().string());
        CHECK(clip.frame_count == e.frames);
        CHECK(clip.joint_count() == e.joints);
        CHECK(clip.frame_rate == Approx(e.rate).epsilon(1e-4));
        CHECK(clip.skeleton.joint_names[0] == e.root);
        CHECK(clip.animated_translation[0]);
        CHECK(std::count(clip.animated_translation.begin(), clip.animated_translation.end(), true) == 1);
        CHECK(!clip.skeleton.end_site_parents.empty());

        // Forward kinematics against the independent matrix reader.
        const RefClip ref = reference_read(test::read_text_file(path));
        REQUIRE(static_cast<int>(ref.joints.size()) == e.joints);
        REQUIRE(static_cast<int>(ref.frames.size()) == e.frames);
        for (int f : {0, 1, e.frames / 3, e.frames / 2, e.frames - 1}) {
            const std::vector<vec3> got = model_positions(clip, f);
            const std::vector<glm::dvec3> want = reference_positions(ref, f);
            double worst = 0.0;
            for (size_t j = 0; j < got.size(); ++j)
                for (int a = 0; a < 3; ++a) worst = std::max(worst, std::abs(static_cast<double>(got[j][a]) - want[j][a]));
            INFO("frame " << f);
            CHECK(worst < kFkTolerance);
        }
    }
    // Every .bvh in the folder imports (new files get at least this much).
    const std::vector<std::string> files = shared_bvh_files();
    CHECK(files.size() >= 4);
    for (const std::string& path : files) {
        INFO(path);
        CHECK(validate_clip(load_bvh_file(path)).ok());
    }
}

TEST_CASE("BVH round trip export→import on the shared files", "[bvh][mocap]") {
    const std::vector<std::string> files = shared_bvh_files();
    if (files.empty()) return;
    for (const std::string& path : files) {
        INFO(path);
        const Clip a = load_bvh_file(path);
        const std::string text = export_bvh(a);
        const Clip b = import_bvh(text, path);
        require_same_skeleton(a.skeleton, b.skeleton);
        require_same_motion(a, b);
        CHECK(b.name == a.name);
        // And the export is a fixed point after one round (apart from float noise
        // in the angles, the same text).
        const Clip c = import_bvh(export_bvh(b), path);
        require_same_motion(b, c);
    }
}

TEST_CASE("BVH round trip of a synthetic clip: gimbal lock, several roots, any joint order", "[bvh]") {
    Clip clip;
    clip.name = "synthetic";
    clip.frame_rate = 60.0;
    Skeleton& s = clip.skeleton;
    // Not depth-first (spine's child comes after leg): the export reorders.
    s.joint_names = {"hips", "spine", "leg", "head", "foot", "prop", "prop_tip"};
    s.parents = {kNoParent, 0, 0, 1, 2, kNoParent, 5};
    s.rest_offsets = {vec3(0, 1, 0), vec3(0, 0.2f, 0.01f), vec3(0.1f, -0.05f, 0), vec3(0, 0.5f, 0),
                      vec3(0, -0.9f, 0.05f), vec3(2, 0, 0), vec3(0, 0.3f, 0)};
    s.end_site_parents = {3, 4, 6};
    s.end_site_offsets = {vec3(0, 0.2f, 0), vec3(0, 0, 0.2f), vec3(0.1f, 0, 0)};
    const size_t joints = 7;
    // hips: root; head: animated non-root; prop: root without the flag; foot: not
    // flagged but its translation changes in one frame (must still survive).
    clip.animated_translation = {true, false, false, true, false, false, false};

    const vec3 x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
    auto zxy = [&](double zd, double xd, double yd) {
        return quat_mul(quat_mul(quat_axis_angle(z, zd * det::kDegToRad), quat_axis_angle(x, xd * det::kDegToRad)),
                        quat_axis_angle(y, yd * det::kDegToRad));
    };
    std::vector<quat> special = {
        quat_identity(),
        quat_wxyz(0, 1, 0, 0),   // 180° about X
        quat_wxyz(0, 0, 1, 0),   // 180° about Y
        quat_wxyz(0, 0, 0, 1),   // 180° about Z
        quat_wxyz(-0.5f, 0.5f, 0.5f, 0.5f),  // negative w
        zxy(30, 90, 40),         // gimbal lock, both signs
        zxy(-120, -90, 75),
        zxy(10, 89.9999, -20),   // next to it
        zxy(170, -89.99, 100),
        zxy(179.9, 0.001, -179.9),
        quat_axis_angle(vec3(0.6f, 0.0f, 0.8f), 1e-6),
    };
    SplitMix rng{12345};
    const int frames = 60;
    clip.frame_count = frames;
    for (int f = 0; f < frames; ++f) {
        for (size_t j = 0; j < joints; ++j) {
            quat q;
            const size_t pick = (static_cast<size_t>(f) * joints + j);
            if (pick < special.size()) {
                q = special[pick];
            } else {
                q = quat_normalize(quat_wxyz(static_cast<float>(rng.unit() * 2 - 1), static_cast<float>(rng.unit() * 2 - 1),
                                             static_cast<float>(rng.unit() * 2 - 1), static_cast<float>(rng.unit() * 2 - 1)));
            }
            clip.rotations.push_back(q);
            vec3 t = s.rest_offsets[j];
            if (clip.animated_translation[j])
                t = vec3(static_cast<float>(rng.unit() * 200 - 100), static_cast<float>(rng.unit() * 2e-3),
                         static_cast<float>(-rng.unit() * 1e4));
            if (j == 4 && f == 17) t = vec3(0.25f, -0.5f, 0.125f);
            clip.translations.push_back(t);
        }
    }
    REQUIRE(validate_clip(clip).ok());

    const std::string text = export_bvh(clip);
    CHECK_THAT(text, Catch::StartsWith("HIERARCHY\nROOT hips\n"));
    CHECK_THAT(text, Catch::Contains("CHANNELS 3 Zrotation Xrotation Yrotation"));
    CHECK_THAT(text, Catch::Contains("CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation"));
    CHECK_THAT(text, Catch::Contains("\nROOT prop\n"));
    CHECK_THAT(text, Catch::Contains("End Site"));
    CHECK_THAT(text, Catch::Contains("Frames: 60\nFrame Time: 0.016666666666666666\n"));

    const Clip back = import_bvh(text, "synthetic.bvh");
    REQUIRE(validate_clip(back).ok());
    CHECK(back.name == "synthetic");
    // Depth-first order after the round trip.
    CHECK(back.skeleton.joint_names ==
          std::vector<std::string>{"hips", "spine", "head", "leg", "foot", "prop", "prop_tip"});
    CHECK(back.skeleton.parents == std::vector<int>{kNoParent, 0, 1, 0, 3, kNoParent, 5});
    for (int j = 0; j < back.joint_count(); ++j) {
        const int k = s.find(back.skeleton.joint_names[static_cast<size_t>(j)]);
        CHECK(back.skeleton.rest_offsets[static_cast<size_t>(j)] == s.rest_offsets[static_cast<size_t>(k)]);
    }
    REQUIRE(back.skeleton.end_site_offsets.size() == 3);
    CHECK(back.animated_translation == std::vector<bool>{true, false, true, false, true, true, false});
    require_same_motion(clip, back);

    // FK agrees as well (positions are what a viewer shows).
    for (int f = 0; f < frames; f += 7) {
        const std::vector<vec3> pa = model_positions(clip, f);
        const std::vector<vec3> pb = model_positions(back, f);
        for (size_t j = 0; j < joints; ++j) {
            const int k = back.skeleton.find(s.joint_names[j]);
            const vec3 d = pa[j] - pb[static_cast<size_t>(k)];
            CHECK(std::abs(d.x) + std::abs(d.y) + std::abs(d.z) < 1e-2f);
        }
    }

    // A clip the format cannot hold is refused.
    Clip bad = clip;
    bad.skeleton.joint_names[1] = "two words";
    CHECK_THROWS_AS(export_bvh(bad), std::invalid_argument);
    bad = clip;
    bad.frame_count = 0;
    CHECK_THROWS_AS(export_bvh(bad), std::invalid_argument);
}

TEST_CASE("BVH malformed input: each error says the line and what was expected", "[bvh]") {
    // A minimal valid file; every case edits one line (1-based) of it.
    const std::vector<std::string> base = {
        "HIERARCHY",                                                                 // 1
        "ROOT hips",                                                                 // 2
        "{",                                                                         // 3
        "  OFFSET 0 0 0",                                                            // 4
        "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",  // 5
        "  End Site",                                                                // 6
        "  {",                                                                       // 7
        "    OFFSET 0 1 0",                                                          // 8
        "  }",                                                                       // 9
        "}",                                                                         // 10
        "MOTION",                                                                    // 11
        "Frames: 2",                                                                 // 12
        "Frame Time: 0.1",                                                           // 13
        "0.0 0.0 0.0 0.0 0.0 0.0",                                                   // 14
        "1.0 2.0 3.0 4.0 5.0 6.0",                                                   // 15
    };
    auto join = [](const std::vector<std::string>& lines) {
        std::string out;
        for (const auto& l : lines) out += l + "\n";
        return out;
    };
    // Line `line` replaced by `text` (which may hold several lines, or be the
    // marker "<delete>").
    auto edit = [&](int line, const std::string& text) {
        std::vector<std::string> lines = base;
        if (text == "<delete>")
            lines.erase(lines.begin() + (line - 1));
        else
            lines[static_cast<size_t>(line - 1)] = text;
        return join(lines);
    };
    REQUIRE(validate_clip(import_bvh(join(base), "ok.bvh")).ok());

    struct Case {
        const char* what;
        std::string text;
        int line;
        const char* message;
    };
    std::string many_joints = "HIERARCHY\nROOT j0\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n";
    for (int i = 1; i <= 1024; ++i) many_joints += "JOINT j" + std::to_string(i) + "\n{\nOFFSET 0 1 0\n}\n";
    // 1024 joints, one channel: 16385 frames fit in the bytes but not the pose limit.
    std::string too_many_samples = "HIERARCHY\nROOT j0\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n";
    for (int i = 1; i < 1024; ++i) too_many_samples += "JOINT j" + std::to_string(i) + "\n{\nOFFSET 0 1 0\n}\n";
    too_many_samples += "}\nMOTION\nFrames: 16385\nFrame Time: 0.1\n";
    const int samples_frames_line = 1 + 4 + 1023 * 4 + 1 + 1 + 1;
    for (int i = 0; i < 16385; ++i) too_many_samples += "0\n";

    const std::vector<Case> cases = {
        {"empty file", "", 1, "expected 'HIERARCHY' at the start of a BVH file, found end of file"},
        {"only blanks", "  \n\t\r\n", 1, "expected 'HIERARCHY'"},
        {"not a BVH", "HELLO world\n", 1, "expected 'HIERARCHY' at the start of a BVH file, found 'HELLO'"},
        {"no ROOT", "HIERARCHY\n", 1, "expected ROOT, found end of file"},
        {"MOTION before ROOT", "HIERARCHY\nMOTION\n", 2, "expected ROOT before MOTION"},
        {"ROOT without name", edit(2, "ROOT"), 2, "expected a joint name (one word) after ROOT"},
        {"name with a space", edit(2, "ROOT left hip"), 2, "expected '{' after joint 'left' (names are one word)"},
        {"missing opening brace", edit(3, "<delete>"), 3, "expected '{' after joint 'hips', found 'OFFSET'"},
        {"missing closing brace", edit(10, "<delete>"), 10,
         "expected '}' to close joint 'hips' opened on line 3, found 'MOTION'"},
        {"missing closing brace at the end", join({base.begin(), base.begin() + 9}), 9,
         "expected '}' to close joint 'hips' opened on line 3, found end of file"},
        {"stray closing brace", edit(10, "}\n}"), 11, "expected ROOT or MOTION, found '}'"},
        {"stray opening brace", edit(4, "{"), 4, "expected OFFSET, CHANNELS, JOINT, End Site or '}' in joint 'hips', found '{'"},
        {"unknown keyword", edit(4, "  OFSET 0 0 0"), 4, "expected OFFSET, CHANNELS, JOINT, End Site or '}'"},
        {"OFFSET short", edit(4, "  OFFSET 0 0"), 4, "OFFSET needs 3 numbers on its line, found 2"},
        {"OFFSET long", edit(4, "  OFFSET 0 0 0 0"), 4, "OFFSET needs 3 numbers on its line, found 4"},
        {"OFFSET not a number", edit(4, "  OFFSET 0 zero 0"), 4, "expected a finite number in OFFSET, found 'zero'"},
        {"OFFSET nan", edit(4, "  OFFSET 0 nan 0"), 4, "expected a finite number in OFFSET, found 'nan'"},
        {"second OFFSET", edit(4, "  OFFSET 0 0 0\n  OFFSET 0 0 0"), 5, "joint 'hips' has a second OFFSET"},
        {"joint without OFFSET", edit(8, "<delete>"), 8, "End Site closes without an OFFSET"},
        {"CHANNELS 7", edit(5, "  CHANNELS 7 Xposition Yposition Zposition Zrotation Xrotation Yrotation Xrotation"), 5,
         "CHANNELS count must be 0 to 6, found '7'"},
        {"CHANNELS 100000", edit(5, "  CHANNELS 100000 Xrotation"), 5, "CHANNELS count must be 0 to 6, found '100000'"},
        {"CHANNELS -1", edit(5, "  CHANNELS -1"), 5, "CHANNELS count must be 0 to 6"},
        {"CHANNELS without count", edit(5, "  CHANNELS"), 5, "expected the channel count after CHANNELS"},
        {"CHANNELS count not a number", edit(5, "  CHANNELS six"), 5, "expected the channel count after CHANNELS, found 'six'"},
        {"CHANNELS lists too few", edit(5, "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation"), 5,
         "CHANNELS 6 expects 6 channel names on its line, found 5"},
        {"CHANNELS lists too many", edit(5, "  CHANNELS 2 Xposition Yposition Zposition"), 5,
         "CHANNELS 2 expects 2 channel names on its line, found 3"},
        {"unknown channel", edit(5, "  CHANNELS 1 Wrotation"), 5, "expected a channel name (Xposition"},
        {"repeated channel", edit(5, "  CHANNELS 2 Xrotation xrotation"), 5, "channel 'xrotation' is listed twice"},
        {"End without Site", edit(6, "  End"), 6, "expected 'Site' after 'End'"},
        {"End Site with channels", edit(8, "    CHANNELS 1 Xrotation"), 8, "an End Site has no CHANNELS"},
        {"joint inside End Site", edit(8, "    OFFSET 0 1 0\n    JOINT x"), 9, "an End Site cannot contain joints"},
        {"duplicate joint name", edit(6, "  JOINT hips"), 6, "duplicate joint name 'hips' (first used on line 2)"},
        {"no MOTION section", join({base.begin(), base.begin() + 10}), 10, "expected MOTION section, found end of file"},
        {"text after MOTION", edit(11, "MOTION now"), 11, "expected end of line after MOTION, found 'now'"},
        {"no Frames line", join({base.begin(), base.begin() + 11}), 11, "expected 'Frames: <count>' after MOTION"},
        {"Frames not a number", edit(12, "Frames: many"), 12, "expected 'Frames: <count>' after MOTION with a whole number"},
        {"Frames fractional", edit(12, "Frames: 2.5"), 12, "with a whole number, found '2.5'"},
        {"Frames zero", edit(12, "Frames: 0"), 12, "Frames must be at least 1"},
        {"Frames negative", edit(12, "Frames: -5"), 12, "Frames must be at least 1"},
        {"Frames absurd", edit(12, "Frames: 2000000000"), 12, "Frames: 2000000000 is more than the file can hold: 2000000000 frames of 6 values need more than the 48 bytes"},
        {"Frames beyond int64", edit(12, "Frames: 99999999999999999999999"), 12, "with a whole number"},
        {"Frames says more than there are", edit(12, "Frames: 3"), 15, "expected 3 frames (Frames: 3), but the file ends after 2"},
        {"Frames says fewer than there are", edit(12, "Frames: 1"), 15,
         "expected end of file after 1 frames (Frames: 1), found another frame line"},
        {"Frame Time missing", edit(13, "<delete>"), 13, "expected 'Frame Time: <seconds>' after Frames, found '0.0 0.0"},
        {"Frame Time zero", edit(13, "Frame Time: 0"), 13, "Frame Time must be at least 1e-6 seconds, found '0'"},
        {"Frame Time negative", edit(13, "Frame Time: -0.1"), 13, "Frame Time must be at least"},
        {"Frame Time inf", edit(13, "Frame Time: inf"), 13, "with a finite number, found 'inf'"},
        {"Frame Time garbage", edit(13, "Frame Time: soon"), 13, "with a finite number, found 'soon'"},
        {"frame line short", edit(14, "0.0 0.0 0.0 0.0 0.0"), 14, "frame 1 has 5 values, expected 6 (one per channel)"},
        {"frame line long", edit(15, "1.0 2.0 3.0 4.0 5.0 6.0 7.0"), 15, "frame 2 has 7 values, expected 6"},
        {"frame value not a number", edit(15, "1.0 2.0 three 4.0 5.0 6.0"), 15,
         "expected a finite number (value 3 of frame 2), found 'three'"},
        {"frame value nan", edit(14, "0.0 NaN 0.0 0.0 0.0 0.0"), 14, "expected a finite number (value 2 of frame 1), found 'NaN'"},
        {"frame value inf", edit(14, "0.0 0.0 -inf 0.0 0.0 0.0"), 14, "found '-inf'"},
        {"frame value overflow", edit(14, "0.0 0.0 1e999 0.0 0.0 0.0"), 14, "value '1e999' is out of range"},
        {"frame value huge", edit(14, "0.0 0.0 1e300 0.0 0.0 0.0"), 14, "value '1e300' is out of range"},
        {"MSVC nan", edit(14, "0.0 0.0 -1.#IND 0.0 0.0 0.0"), 14, "found '-1.#IND'"},
        {"no channels anywhere", edit(5, "  CHANNELS 0"), 12, "no joint has CHANNELS"},
        {"NUL byte", edit(8, std::string("    OFFSET 0 1\0 0", 17)), 8, "unexpected control byte 0x00"},
        {"escape byte", edit(2, "ROOT \x1b[31mhips"), 2, "unexpected control byte 0x1B"},
        {"too many joints", many_joints, 6 + 4 * 1023, "too many joints: more than 1024"},
        {"too many pose samples", too_many_samples, samples_frames_line, "exceeds the limit of 16777216 pose samples"},
    };
    int checked = 0;
    for (const Case& c : cases) {
        INFO("case: " << c.what);
        try {
            import_bvh(c.text, "bad.bvh");
            FAIL("no ImportError");
        } catch (const ImportError& e) {
            CHECK(e.file() == "bad.bvh");
            CHECK(e.line() == c.line);
            CHECK_THAT(e.message(), Catch::Contains(c.message));
            CHECK_THAT(std::string(e.what()), Catch::StartsWith("bad.bvh:" + std::to_string(c.line) + ": "));
            ++checked;
        }
    }
    CHECK(checked == static_cast<int>(cases.size()));
}

TEST_CASE("BVH hierarchy 100000 deep is refused without recursion", "[bvh]") {
    constexpr int kDepth = 100000;
    std::string text = "HIERARCHY\n";
    text.reserve(static_cast<size_t>(kDepth) * 40);
    for (int i = 0; i < kDepth; ++i)
        text += (i == 0 ? "ROOT j" : "JOINT j") + std::to_string(i) + "\n{\nOFFSET 0 1 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n";
    for (int i = 0; i < kDepth; ++i) text += "}\n";
    text += "MOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0\n";
    try {
        import_bvh(text, "deep.bvh");
        FAIL("no ImportError");
    } catch (const ImportError& e) {
        // Joint 1025 (0-based 1024) is named on line 2 + 4·1024.
        CHECK(e.line() == 2 + 4 * 1024);
        CHECK_THAT(e.message(), Catch::Contains("too many joints"));
    }
    // Braces alone, 100000 deep.
    const std::string braces = "HIERARCHY\nROOT a\n" + std::string(kDepth, '{');
    REQUIRE_THROWS_AS(import_bvh(braces, "braces.bvh"), ImportError);

    // The deepest chain allowed imports, and exports without recursion.
    std::string chain = "HIERARCHY\n";
    for (int i = 0; i < 1024; ++i)
        chain += (i == 0 ? "ROOT j" : "JOINT j") + std::to_string(i) + "\n{\nOFFSET 0 1 0\nCHANNELS 1 Zrotation\n";
    for (int i = 0; i < 1024; ++i) chain += "}\n";
    chain += "MOTION\nFrames: 1\nFrame Time: 0.1\n";
    for (int i = 0; i < 1024; ++i) chain += "1 ";
    chain += "\n";
    const Clip deep = import_bvh(chain, "chain.bvh");
    CHECK(deep.joint_count() == 1024);
    CHECK(deep.skeleton.parents[1023] == 1022);
    const Clip again = import_bvh(export_bvh(deep), "chain.bvh");
    CHECK(again.skeleton.parents == deep.skeleton.parents);
    require_same_motion(deep, again);
}

TEST_CASE("BVH binary garbage and token soup never crash", "[bvh]") {
    SplitMix rng{99};
    for (int i = 0; i < 300; ++i) {
        std::string junk(1 + rng.below(4096), '\0');
        for (char& c : junk) c = static_cast<char>(rng.below(256));
        CHECK_FALSE(parses_or_import_error(junk));
    }
    // A valid header followed by binary data.
    std::string half = "HIERARCHY\nROOT a\n{\n";
    for (int i = 0; i < 64; ++i) half += static_cast<char>(0x80 + i * 2);
    half += std::string("\x00\x01\x02", 3);
    try {
        import_bvh(half, "half.bvh");
        FAIL("no ImportError");
    } catch (const ImportError& e) {
        CHECK(e.line() == 4);
        CHECK_THAT(e.message(), Catch::Contains("binary file"));
    }

    // Printable soup from the BVH vocabulary reaches deeper into the parser.
    const std::vector<std::string> vocabulary = {
        "HIERARCHY", "ROOT", "JOINT", "End", "Site", "{", "}", "OFFSET", "CHANNELS", "MOTION", "Frames:", "Frame",
        "Time:", "0", "1", "3", "6", "7", ".5", "-1e3", "nan", "1e999", "Xposition", "Yrotation", "Zrotation", "a", "b",
        "\n", "\n", "\n", "\r\n", "\r", " ", "\t"};
    int parsed = 0;
    for (int i = 0; i < 3000; ++i) {
        std::string soup = i % 2 ? "HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n" : "";
        const size_t n = rng.below(80);
        for (size_t k = 0; k < n; ++k) soup += vocabulary[rng.below(vocabulary.size())] + " ";
        if (parses_or_import_error(soup)) ++parsed;
    }
    CHECK(parsed >= 0);  // reaching here without another exception is the test
}

TEST_CASE("BVH truncated at every offset parses or throws ImportError", "[bvh]") {
    for (const char* name : {"channel_order.bvh", "formats.bvh"}) {
        const std::string text = fixture(name);
        int parsed = 0;
        for (size_t n = 0; n <= text.size(); ++n)
            if (parses_or_import_error(text.substr(0, n))) ++parsed;
        INFO(name);
        // Only cuts inside or after the last frame line can still be complete.
        CHECK(parsed >= 1);
        CHECK(parsed < 40);
    }
    // Mutations of a valid file: one byte replaced, inserted or deleted.
    const std::string text = fixture("channel_order.bvh");
    SplitMix rng{7};
    for (int i = 0; i < 3000; ++i) {
        std::string m = text;
        const size_t at = rng.below(m.size());
        const char c = "0123456789.-+eE{} \n\r\tXZabc\0"[rng.below(28)];
        switch (i % 3) {
            case 0: m[at] = c; break;
            case 1: m.insert(at, 1, c); break;
            default: m.erase(at, 1); break;
        }
        parses_or_import_error(m);
    }
    // A real file cut anywhere in its hierarchy and first frames.
    const std::string dir = test::mocap_dir();
    if (dir.empty()) return;
    const std::string real = test::read_text_file(dir + "/cmu_bvh_131/131_01.bvh");
    const size_t limit = std::min<size_t>(real.size(), 8000);
    for (size_t n = 0; n < limit; ++n) CHECK_FALSE(parses_or_import_error(real.substr(0, n)));
    // And near the end: a cut inside the last line still has all its frames
    // only when it falls after the last value's first character.
    for (size_t n = real.size() - 64; n <= real.size(); ++n) parses_or_import_error(real.substr(0, n));
}

TEST_CASE("load_bvh_file names the path in errors and the clip after the file", "[bvh]") {
    const std::string missing = test::source_path("tests/data/bvh/no_such_file.bvh");
    try {
        load_bvh_file(missing);
        FAIL("no ImportError");
    } catch (const ImportError& e) {
        CHECK(e.file() == missing);
        CHECK(e.line() == 0);
        CHECK_THAT(std::string(e.what()), Catch::Contains(missing));
        CHECK_THAT(e.message(), Catch::Contains("cannot open"));
    }
    // A directory is not readable as a file.
    const std::string dir = test::source_path("tests/data/bvh");
    CHECK_THROWS_AS(load_bvh_file(dir), ImportError);

    const Clip clip = load_bvh_file(test::source_path("tests/data/bvh/channel_order.bvh"));
    CHECK(clip.name == "channel_order");
    // Errors from the parse carry the path too.
    try {
        import_bvh("HIERARCHY\nROOT\n", "some/dir/x.bvh");
        FAIL("no ImportError");
    } catch (const ImportError& e) {
        CHECK_THAT(std::string(e.what()), Catch::StartsWith("some/dir/x.bvh:2: "));
    }
    CHECK(import_bvh(fixture("channel_order.bvh"), "C:\\clips\\walk.fast.bvh").name == "walk.fast");
}

TEST_CASE("BVH export text: ZXY channels, end sites, enough digits", "[bvh]") {
    const Clip clip = import_bvh(fixture("channel_order.bvh"), "channel_order.bvh");
    const std::string text = export_bvh(clip);
    CHECK_THAT(text, Catch::StartsWith("HIERARCHY\nROOT root\n{\n\tOFFSET 0 0 0\n"
                                       "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
                                       "\tJOINT arm\n\t{\n\t\tOFFSET 0 1 0\n\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n"));
    CHECK_THAT(text, Catch::Contains("\t\t\tEnd Site\n\t\t\t{\n\t\t\t\tOFFSET 0 0 1\n\t\t\t}\n"));
    CHECK_THAT(text, Catch::Contains("MOTION\nFrames: 5\nFrame Time: 0.5\n"));
    // Translations are written exactly; rest frames as zero angles.
    CHECK_THAT(text, Catch::Contains("\n0 0 0 0 0 0 0 0 0 1 2 0 0 0 0\n10 20 30 "));
    const Clip back = import_bvh(text, "channel_order.bvh");
    require_same_skeleton(clip.skeleton, back.skeleton);
    require_same_motion(clip, back);
}
