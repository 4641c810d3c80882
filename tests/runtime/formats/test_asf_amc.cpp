#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "runtime/formats/asf_amc.hpp"
#include "tests/test_support.hpp"

using namespace marionette;

namespace {

// ---------------------------------------------------------------- helpers

struct ModelPose {
    std::vector<quat> rotations;
    std::vector<vec3> positions;
};

ModelPose model_pose(const Clip& clip, int frame) {
    const auto n = static_cast<std::size_t>(clip.joint_count());
    ModelPose pose{std::vector<quat>(n), std::vector<vec3>(n)};
    const LocalToModelJob job{clip.skeleton.parents,
                              {{clip.frame_rotations(frame), n}, {clip.frame_translations(frame), n}},
                              {pose.rotations, pose.positions}};
    REQUIRE(job.validate());
    REQUIRE(job.run());
    return pose;
}

// Model-space end of every end site.
std::vector<vec3> end_site_positions(const Skeleton& sk, const ModelPose& pose) {
    std::vector<vec3> out;
    for (std::size_t e = 0; e < sk.end_site_parents.size(); ++e) {
        const auto p = static_cast<std::size_t>(sk.end_site_parents[e]);
        out.push_back(pose.positions[p] + quat_rotate(pose.rotations[p], sk.end_site_offsets[e]));
    }
    return out;
}

void check_vec(vec3 got, vec3 expected, double tolerance = 1e-5) {
    INFO("got (" << got.x << ", " << got.y << ", " << got.z << "), expected (" << expected.x << ", " << expected.y
                 << ", " << expected.z << ")");
    CHECK(std::abs(got.x - expected.x) < tolerance);
    CHECK(std::abs(got.y - expected.y) < tolerance);
    CHECK(std::abs(got.z - expected.z) < tolerance);
}

std::vector<std::string> split_lines(const std::string& text) {
    std::vector<std::string> lines;
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) lines.push_back(line);
    return lines;
}

std::string join_lines(const std::vector<std::string>& lines) {
    std::string out;
    for (const std::string& l : lines) out += l + "\n";
    return out;
}

// Replaces 1-based line n (the replacement may hold several lines).
std::string with_line(const std::string& text, int n, const std::string& replacement) {
    std::vector<std::string> lines = split_lines(text);
    lines.at(static_cast<std::size_t>(n - 1)) = replacement;
    return join_lines(lines);
}

std::string first_lines(const std::string& text, int n) {
    std::vector<std::string> lines = split_lines(text);
    lines.resize(static_cast<std::size_t>(n));
    return join_lines(lines);
}

bool is_integer_line(const std::string& line) {
    std::istringstream in(line);
    std::string word, extra;
    if (!(in >> word) || (in >> extra)) return false;
    for (char c : word)
        if (c < '0' || c > '9') return false;
    return true;
}

// ---------------------------------------------------------------- tiny files

// Line numbers matter: the malformed cases below edit single lines.
const std::string kTinyAsf =
    "# tiny skeleton for hand-checked FK\n"  // 1
    ":version 1.10\n"                        // 2
    ":name tiny\n"                           // 3
    ":units\n"                               // 4
    "  mass 1.0\n"                           // 5
    "  length 1\n"                           // 6
    "  angle deg\n"                          // 7
    ":documentation\n"                       // 8
    "  two bones, # and : inside text\n"     // 9
    ":root\n"                                // 10
    "  order TX TY TZ RX RY RZ\n"            // 11
    "  axis XYZ\n"                           // 12
    "  position 0 0 0\n"                     // 13
    "  orientation 0 0 0\n"                  // 14
    ":bonedata\n"                            // 15
    "  begin\n"                              // 16
    "    id 1\n"                             // 17
    "    name a\n"                           // 18
    "    direction 0 1 0\n"                  // 19
    "    length 2\n"                         // 20
    "    axis 0 0 0 XYZ\n"                   // 21
    "    dof rx ry rz\n"                     // 22
    "    limits (-180 180)\n"                // 23
    "           (-180 180)\n"                // 24
    "           (-180 180)\n"                // 25
    "  end\n"                                // 26
    "  begin\n"                              // 27
    "    id 2\n"                             // 28
    "    name b\n"                           // 29
    "    direction 1 0 0\n"                  // 30
    "    length 3\n"                         // 31
    "    axis 0 0 90 XYZ\n"                  // 32
    "    dof rx\n"                           // 33
    "    limits (-180.0 180.0)\n"            // 34
    "  end\n"                                // 35
    ":hierarchy\n"                           // 36
    "  begin\n"                              // 37
    "    root a\n"                           // 38
    "    a b\n"                              // 39
    "  end\n";                               // 40

const std::string kTinyAmc =
    "#!OML:ASF tiny.asf\n"    // 1
    ":FULLY-SPECIFIED\n"      // 2
    ":DEGREES\n"              // 3
    "1\n"                     // 4
    "root 10 0 0 0 0 0\n"     // 5
    "a 0 0 90\n"              // 6
    "b 90\n"                  // 7
    "2\n"                     // 8
    "root 0 0 0 0 0 0\n"      // 9
    "a 90 90 0\n"             // 10
    "b 0\n"                   // 11
    "3\n"                     // 12
    "root 0 0 0 0 0 90\n"     // 13
    "a 0 0 0\n"               // 14
    "b 0\n";                  // 15

Clip import_tiny(const std::string& asf, const std::string& amc) {
    return import_asf_amc(asf, "tiny.asf", amc, "tiny.amc");
}

// A chain root → b0 → b1 → ... along +Y, one rx dof per bone. The bone block
// of bone k begins on line chain_begin_line(k).
constexpr int kChainHeaderLines = 8;
std::string chain_asf(int bones) {
    std::string s = ":units\n  length 1\n  angle deg\n:root\n  order TX TY TZ RX RY RZ\n  axis XYZ\n"
                    "  position 0 0 0\n  orientation 0 0 0\n:bonedata\n";
    for (int k = 0; k < bones; ++k)
        s += "begin\nname b" + std::to_string(k) + "\ndirection 0 1 0\nlength 1\naxis 0 0 0 XYZ\ndof rx\nend\n";
    s += ":hierarchy\nbegin\nroot b0\n";
    for (int k = 1; k < bones; ++k) s += "b" + std::to_string(k - 1) + " b" + std::to_string(k) + "\n";
    s += "end\n";
    return s;
}
int chain_begin_line(int k) { return kChainHeaderLines + 2 + 7 * k; }

// ---------------------------------------------------------------- reference

// An independent reader of the CMU files (which are regular) and the textbook
// Acclaim forward kinematics in double precision with libm:
//   W_b = W_parent · C_b · M_b · C_bᵀ,  end_b = end_parent + W_b · dir_b · len_b,
// C_b = Rz·Ry·Rx of `axis`, M_b the dof rotations in listed order.
using Mat3 = std::array<double, 9>;  // row-major

Mat3 mat_mul(const Mat3& a, const Mat3& b) {
    Mat3 r{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) r[i * 3 + j] += a[i * 3 + k] * b[k * 3 + j];
    return r;
}

Mat3 mat_transpose(const Mat3& a) {
    return {a[0], a[3], a[6], a[1], a[4], a[7], a[2], a[5], a[8]};
}

Mat3 mat_axis(int axis, double degrees) {
    const double r = degrees * 3.14159265358979323846 / 180.0;
    const double c = std::cos(r), s = std::sin(r);
    if (axis == 0) return {1, 0, 0, 0, c, -s, 0, s, c};
    if (axis == 1) return {c, 0, s, 0, 1, 0, -s, 0, c};
    return {c, -s, 0, s, c, 0, 0, 0, 1};
}

std::array<double, 3> mat_apply(const Mat3& m, const std::array<double, 3>& v) {
    return {m[0] * v[0] + m[1] * v[1] + m[2] * v[2], m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
            m[6] * v[0] + m[7] * v[1] + m[8] * v[2]};
}

struct RefBone {
    std::array<double, 3> direction{};
    double length = 0.0;
    std::array<double, 3> axis{};
    std::vector<int> dofs;  // 0, 1, 2 for rx, ry, rz
};

struct RefAsf {
    std::map<std::string, RefBone> bones;
    std::vector<std::pair<std::string, std::string>> edges;  // (parent, child), file order
    int dof_total = 6;                                       // the root's
};

RefAsf read_ref_asf(const std::string& text) {
    RefAsf ref;
    std::istringstream in(text);
    std::string line;
    bool in_bonedata = false, in_hierarchy = false;
    std::string name;
    RefBone bone;
    while (std::getline(in, line)) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        std::istringstream words(line);
        std::string key;
        if (!(words >> key)) continue;
        if (key == ":bonedata") in_bonedata = true;
        if (key == ":hierarchy") {
            in_bonedata = false;
            in_hierarchy = true;
        }
        if (in_bonedata) {
            if (key == "begin") bone = RefBone{};
            if (key == "name") words >> name;
            if (key == "direction") words >> bone.direction[0] >> bone.direction[1] >> bone.direction[2];
            if (key == "length") words >> bone.length;
            if (key == "axis") words >> bone.axis[0] >> bone.axis[1] >> bone.axis[2];
            if (key == "dof")
                for (std::string d; words >> d;) bone.dofs.push_back(d[1] - 'x');
            if (key == "end") {
                ref.bones[name] = bone;
                ref.dof_total += static_cast<int>(bone.dofs.size());
            }
        } else if (in_hierarchy && key != "begin" && key != "end" && key != ":hierarchy") {
            for (std::string child; words >> child;) ref.edges.emplace_back(key, child);
        }
    }
    return ref;
}

// Values of frame `number` (1-based), by bone name.
std::map<std::string, std::vector<double>> read_ref_frame(const std::string& amc, int number) {
    std::map<std::string, std::vector<double>> values;
    std::istringstream in(amc);
    std::string line;
    bool inside = false;
    while (std::getline(in, line)) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (is_integer_line(line)) {
            if (inside) break;
            inside = std::stoi(line) == number;
            continue;
        }
        if (!inside) continue;
        std::istringstream words(line);
        std::string name;
        words >> name;
        for (double v; words >> v;) values[name].push_back(v);
    }
    return values;
}

struct RefPose {
    std::map<std::string, std::array<double, 3>> end;  // bone end; "root" → root position
    std::map<std::string, Mat3> world;
};

RefPose ref_fk(const RefAsf& asf, const std::map<std::string, std::vector<double>>& frame) {
    RefPose pose;
    const std::vector<double>& r = frame.at("root");
    pose.end["root"] = {r[0], r[1], r[2]};
    pose.world["root"] = mat_mul(mat_axis(2, r[5]), mat_mul(mat_axis(1, r[4]), mat_axis(0, r[3])));
    for (const auto& [parent, child] : asf.edges) {  // parents come first in the CMU file
        const RefBone& b = asf.bones.at(child);
        const Mat3 c = mat_mul(mat_axis(2, b.axis[2]), mat_mul(mat_axis(1, b.axis[1]), mat_axis(0, b.axis[0])));
        Mat3 m = mat_axis(0, 0.0);
        const auto it = frame.find(child);
        for (std::size_t i = 0; i < b.dofs.size(); ++i) m = mat_mul(mat_axis(b.dofs[i], it->second.at(i)), m);
        const Mat3 w = mat_mul(pose.world.at(parent), mat_mul(c, mat_mul(m, mat_transpose(c))));
        const double n = std::sqrt(b.direction[0] * b.direction[0] + b.direction[1] * b.direction[1] +
                                   b.direction[2] * b.direction[2]);
        const std::array<double, 3> d = {b.direction[0] * b.length / n, b.direction[1] * b.length / n,
                                         b.direction[2] * b.length / n};
        const std::array<double, 3> step = mat_apply(w, d);
        const std::array<double, 3>& start = pose.end.at(parent);
        pose.end[child] = {start[0] + step[0], start[1] + step[1], start[2] + step[2]};
        pose.world[child] = w;
    }
    return pose;
}

vec3 to_vec3(const std::array<double, 3>& v) {
    return vec3(static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]));
}

struct CmuClip {
    const char* name;
    int frames;  // 0: count from the file
};

const CmuClip kCmuClips[] = {{"16_11", 534}, {"16_15", 471}, {"16_17", 518}, {"16_19", 410}, {"16_33", 0},
                             {"16_35", 162}, {"16_41", 160}, {"16_43", 210}, {"16_57", 268}};

}  // namespace

// ---------------------------------------------------------------- CMU data

TEST_CASE("ASF skeleton of CMU subject 16", "[asf_amc]") {
    const std::string dir = test::mocap_dir();
    if (dir.empty()) return;
    const std::string asf_text = test::read_text_file(dir + "/cmu_amc_16/16.asf");
    const Skeleton sk = import_asf_skeleton(asf_text, "16.asf");
    REQUIRE(validate_skeleton(sk).ok());
    CHECK(sk.joint_count() == 31);
    CHECK(sk.joint_names[0] == "root");
    CHECK(sk.parents[0] == kNoParent);
    // Depth first, children in hierarchy order, as in the CMU BVH conversions.
    CHECK(sk.joint_names[1] == "lhipjoint");
    CHECK(sk.joint_names[2] == "lfemur");
    // Joints sit at bone starts: lfemur at the end of lhipjoint.
    const int lfemur = sk.find("lfemur");
    const int ltibia = sk.find("ltibia");
    REQUIRE(lfemur > 0);
    REQUIRE(ltibia > 0);
    CHECK(sk.joint_names[static_cast<std::size_t>(sk.parents[static_cast<std::size_t>(lfemur)])] == "lhipjoint");
    check_vec(sk.rest_offsets[static_cast<std::size_t>(lfemur)], vec3(0.635348f, -0.713158f, 0.296208f) * 2.47672f,
              1e-4);
    check_vec(sk.rest_offsets[static_cast<std::size_t>(ltibia)], vec3(0.34202f, -0.939693f, 0.0f) * 7.03469f, 1e-4);
    check_vec(sk.rest_offsets[static_cast<std::size_t>(sk.find("lhipjoint"))], vec3(0.0f));
    // Leaves: ltoes, rtoes, head, lfingers, lthumb, rfingers, rthumb.
    CHECK(sk.end_site_parents.size() == 7);
    const RefAsf ref = read_ref_asf(asf_text);
    CHECK(ref.bones.size() == 30);
    CHECK(ref.dof_total == 62);
}

TEST_CASE("every CMU subject 16 AMC clip imports with its frame count", "[asf_amc]") {
    const std::string dir = test::mocap_dir();
    if (dir.empty()) return;
    const std::string asf_path = dir + "/cmu_amc_16/16.asf";
    const RefAsf ref = read_ref_asf(test::read_text_file(asf_path));
    for (const CmuClip& c : kCmuClips) {
        INFO("clip " << c.name);
        const std::string amc_path = dir + "/cmu_amc_16/" + c.name + ".amc";
        const std::string amc_text = test::read_text_file(amc_path);
        int expected = c.frames;
        if (expected == 0)
            for (const std::string& line : split_lines(amc_text)) expected += is_integer_line(line) ? 1 : 0;
        // Frame 1 carries a value for each of the 62 DOFs.
        int values = 0;
        for (const auto& [bone, v] : read_ref_frame(amc_text, 1)) values += static_cast<int>(v.size());
        CHECK(values == ref.dof_total);

        const Clip clip = load_asf_amc_files(asf_path, amc_path);
        CHECK(validate_clip(clip).ok());
        CHECK(clip.name == c.name);
        CHECK(clip.frame_count == expected);
        CHECK(clip.joint_count() == 31);
        CHECK(clip.frame_rate == 120.0);
        CHECK(clip.length_unit == 0.45);
        REQUIRE(clip.animated_translation.size() == 31);
        CHECK(clip.animated_translation[0]);
        for (std::size_t j = 1; j < 31; ++j) CHECK_FALSE(clip.animated_translation[j]);
    }
    const Clip slow = load_asf_amc_files(asf_path, dir + "/cmu_amc_16/16_33.amc", AmcOptions{60.0});
    CHECK(slow.frame_count == 285);  // the README's count, beside the one counted above
    CHECK(slow.frame_rate == 60.0);
}

TEST_CASE("FK of CMU clips keeps every ASF bone length", "[asf_amc]") {
    const std::string dir = test::mocap_dir();
    if (dir.empty()) return;
    const std::string asf_path = dir + "/cmu_amc_16/16.asf";
    const RefAsf ref = read_ref_asf(test::read_text_file(asf_path));
    for (const char* name : {"16_11", "16_35", "16_57"}) {
        const Clip clip = load_asf_amc_files(asf_path, dir + "/cmu_amc_16/" + name + ".amc");
        const Skeleton& sk = clip.skeleton;
        for (int frame : {0, clip.frame_count / 2, clip.frame_count - 1}) {
            INFO("clip " << name << " frame " << frame);
            const ModelPose pose = model_pose(clip, frame);
            for (std::size_t j = 1; j < pose.positions.size(); ++j) {
                const auto p = static_cast<std::size_t>(sk.parents[j]);
                const double distance = glm::length(pose.positions[j] - pose.positions[p]);
                // A joint is its parent bone's end; the root's children start at the root.
                const double expected = p == 0 ? 0.0 : ref.bones.at(sk.joint_names[p]).length;
                INFO("joint " << sk.joint_names[j]);
                CHECK(distance == Approx(expected).margin(1e-4));
            }
            const std::vector<vec3> ends = end_site_positions(sk, pose);
            for (std::size_t e = 0; e < ends.size(); ++e) {
                const auto p = static_cast<std::size_t>(sk.end_site_parents[e]);
                CHECK(glm::length(ends[e] - pose.positions[p]) ==
                      Approx(ref.bones.at(sk.joint_names[p]).length).margin(1e-4));
            }
        }
    }
}

TEST_CASE("FK of CMU clips matches the textbook Acclaim formulation", "[asf_amc]") {
    const std::string dir = test::mocap_dir();
    if (dir.empty()) return;
    const std::string asf_path = dir + "/cmu_amc_16/16.asf";
    const RefAsf ref = read_ref_asf(test::read_text_file(asf_path));
    for (const char* name : {"16_11", "16_41"}) {
        const std::string amc_path = dir + "/cmu_amc_16/" + name + ".amc";
        const std::string amc_text = test::read_text_file(amc_path);
        const Clip clip = load_asf_amc_files(asf_path, amc_path);
        const Skeleton& sk = clip.skeleton;
        for (int frame : {0, 57, clip.frame_count - 1}) {
            INFO("clip " << name << " frame " << frame);
            const RefPose expected = ref_fk(ref, read_ref_frame(amc_text, frame + 1));
            const ModelPose pose = model_pose(clip, frame);
            for (std::size_t j = 0; j < pose.positions.size(); ++j) {
                INFO("joint " << sk.joint_names[j]);
                // Joint j is at its parent bone's end (the root's children at the root).
                const std::string start = j == 0 ? "root" : sk.joint_names[static_cast<std::size_t>(sk.parents[j])];
                check_vec(pose.positions[j], to_vec3(expected.end.at(start)), 2e-3);
                // Same world rotation: compare the images of two axes.
                const Mat3& w = expected.world.at(sk.joint_names[j]);
                check_vec(quat_rotate(pose.rotations[j], vec3(1, 0, 0)), to_vec3(mat_apply(w, {1, 0, 0})), 1e-5);
                check_vec(quat_rotate(pose.rotations[j], vec3(0, 1, 0)), to_vec3(mat_apply(w, {0, 1, 0})), 1e-5);
            }
            const std::vector<vec3> ends = end_site_positions(sk, pose);
            for (std::size_t e = 0; e < ends.size(); ++e)
                check_vec(ends[e], to_vec3(expected.end.at(sk.joint_names[static_cast<std::size_t>(sk.end_site_parents[e])])),
                          2e-3);
        }
    }
}

// ---------------------------------------------------------------- hand-checked

TEST_CASE("FK of a tiny ASF/AMC matches hand-computed positions", "[asf_amc]") {
    const Clip clip = import_tiny(kTinyAsf, kTinyAmc);
    REQUIRE(validate_clip(clip).ok());
    CHECK(clip.name == "tiny");
    CHECK(clip.frame_count == 3);
    CHECK(clip.length_unit == 1.0);
    REQUIRE(clip.joint_count() == 3);
    CHECK((clip.skeleton.joint_names == std::vector<std::string>{"root", "a", "b"}));
    check_vec(clip.skeleton.rest_offsets[1], vec3(0, 0, 0));
    check_vec(clip.skeleton.rest_offsets[2], vec3(0, 2, 0));
    REQUIRE(clip.skeleton.end_site_parents == std::vector<int>{2});
    check_vec(clip.skeleton.end_site_offsets[0], vec3(3, 0, 0));

    // Frame 1: root at x=10; a turns 90° about z, so b starts at 10 − 2 = 8 on x.
    // b's axis frame is Rz(90°), so its rx dof turns about global y:
    // L_b = Rz·Rx·Rz⁻¹ = Ry(90°), and its end (3, 0, 0) → Rz·Ry·(3,0,0) = (0, 0, −3).
    ModelPose pose = model_pose(clip, 0);
    check_vec(pose.positions[0], vec3(10, 0, 0));
    check_vec(pose.positions[1], vec3(10, 0, 0));
    check_vec(pose.positions[2], vec3(8, 0, 0));
    check_vec(end_site_positions(clip.skeleton, pose)[0], vec3(8, 0, -3));

    // Frame 2: a has rx=90 then ry=90, X first: Ry·Rx·(0,2,0) = Ry·(0,0,2) = (2,0,0).
    // (The other order would give (0,0,2).)
    pose = model_pose(clip, 1);
    check_vec(pose.positions[2], vec3(2, 0, 0));
    check_vec(end_site_positions(clip.skeleton, pose)[0], vec3(2, 0, -3));

    // Frame 3: the root turns 90° about z and carries both bones.
    pose = model_pose(clip, 2);
    check_vec(pose.positions[0], vec3(0, 0, 0));
    check_vec(pose.positions[2], vec3(-2, 0, 0));
    check_vec(end_site_positions(clip.skeleton, pose)[0], vec3(-2, 3, 0));
}

TEST_CASE("ASF radians, root orientation and the AMC angle header", "[asf_amc]") {
    SECTION("angle rad in the ASF, root axis frame Rz(90°)") {
        std::string asf = with_line(kTinyAsf, 7, "  angle rad");
        asf = with_line(asf, 14, "  orientation 0 0 1.5707963267948966");
        asf = with_line(asf, 32, "    axis 0 0 1.5707963267948966 XYZ");
        // Root rx in the root frame Rz(90°) turns about global y:
        // Ry·(0,2,0) = (0,2,0) and the end Ry·(3,0,0) = (0,0,−3).
        const Clip clip = import_tiny(asf, "1\nroot 0 0 0 1.5707963267948966 0 0\na 0 0 0\nb 0\n");
        const ModelPose pose = model_pose(clip, 0);
        check_vec(pose.positions[2], vec3(0, 2, 0));
        check_vec(end_site_positions(clip.skeleton, pose)[0], vec3(0, 2, -3));
    }
    SECTION(":RADIANS in the AMC overrides the ASF's degrees") {
        const Clip clip = import_tiny(kTinyAsf, ":RADIANS\n1\nroot 0 0 0 0 0 1.5707963267948966\na 0 0 0\nb 0\n");
        const ModelPose pose = model_pose(clip, 0);
        check_vec(pose.positions[2], vec3(-2, 0, 0));
    }
    SECTION("root translation replaces the ASF root position") {
        const Clip clip = import_tiny(with_line(kTinyAsf, 13, "  position 5 6 7"), kTinyAmc);
        CHECK(clip.skeleton.rest_offsets[0] == vec3(5, 6, 7));
        check_vec(model_pose(clip, 0).positions[0], vec3(10, 0, 0));
    }
}

TEST_CASE("ASF/AMC tolerate CRLF, tabs, comments and any hierarchy line order", "[asf_amc]") {
    std::string asf;
    for (const std::string& line : split_lines(kTinyAsf)) asf += "\t" + line + "   # note\r\n";
    asf = "\xEF\xBB\xBF" + asf;
    std::string amc;
    for (const std::string& line : split_lines(kTinyAmc)) amc += line + " \t\r\n";
    const Clip crlf = import_tiny(asf, amc);
    const Clip plain = import_tiny(kTinyAsf, kTinyAmc);
    REQUIRE(crlf.frame_count == plain.frame_count);
    CHECK(crlf.rotations == plain.rotations);
    CHECK(crlf.translations == plain.translations);

    // Children listed before their parents, limits on one line with spaces.
    std::string reordered = with_line(kTinyAsf, 38, "    a b");
    reordered = with_line(reordered, 39, "    root a");
    reordered = with_line(reordered, 23, "    limits ( -180 180 ) (-inf inf)(-180 180)");
    reordered = with_line(reordered, 24, "");
    reordered = with_line(reordered, 25, "");
    const Clip other = import_tiny(reordered, kTinyAmc);
    CHECK(other.skeleton.joint_names == plain.skeleton.joint_names);
    CHECK(other.rotations == plain.rotations);
}

TEST_CASE("a 1000-bone chain imports without recursion", "[asf_amc]") {
    constexpr int kBones = 1000;
    std::string amc = "1\nroot 0 0 0 0 0 0\n";
    for (int k = 0; k < kBones; ++k) amc += "b" + std::to_string(k) + " 0\n";
    const Clip clip = import_asf_amc(chain_asf(kBones), "chain.asf", amc, "chain.amc");
    REQUIRE(clip.joint_count() == kBones + 1);
    for (int j = 1; j <= kBones; ++j) CHECK(clip.skeleton.parents[static_cast<std::size_t>(j)] == j - 1);
    const ModelPose pose = model_pose(clip, 0);
    check_vec(pose.positions[kBones], vec3(0, kBones - 1, 0));
}

// ---------------------------------------------------------------- malformed

namespace {

struct BadCase {
    const char* what;
    std::string asf;
    std::string amc;
    const char* file;  // "tiny.asf" or "tiny.amc"
    int line;
    const char* message;
};

void check_bad(const BadCase& c) {
    INFO(c.what);
    try {
        import_tiny(c.asf, c.amc);
        FAIL("no ImportError");
    } catch (const ImportError& e) {
        INFO("message: " << e.what());
        CHECK(e.file() == c.file);
        CHECK(e.line() == c.line);
        CHECK_THAT(e.message(), Catch::Contains(c.message));
    }
}

}  // namespace

TEST_CASE("malformed ASF files fail with file, line and what was expected", "[asf_amc]") {
    const std::string& a = kTinyAsf;
    const std::string& m = kTinyAmc;
    const std::string cycle = with_line(with_line(a, 38, "    root"), 39, "    a b\n    b a");
    const std::string no_bonedata = [&] {
        std::string s = a;
        for (int n = 15; n <= 35; ++n) s = with_line(s, n, "");
        return s;
    }();
    const BadCase cases[] = {
        {"empty", "", m, "tiny.asf", 1, "expected a ':root' section, found end of file"},
        {"binary", std::string("\x7f" "ELF\x02\x01\x01\x00\x00", 9), m, "tiny.asf", 1, "control byte 0x7F"},
        {"binary on line 3", "# a\n# b\n\x89PNG\x1a\n", m, "tiny.asf", 3, "control byte 0x1A"},
        {"not an ASF", "hello world\n", m, "tiny.asf", 1, "expected an ASF section keyword"},
        {"truncated in a bone", first_lines(a, 25), m, "tiny.asf", 25,
         "expected 'end' to close the bone block opened on line 16, found end of file"},
        {"begin inside a bone", with_line(a, 26, "  begin"), m, "tiny.asf", 26,
         "expected 'end' to close the bone block opened on line 16, found 'begin'"},
        {"section inside a bone", with_line(a, 35, ":hierarchy"), m, "tiny.asf", 35,
         "expected 'end' to close the bone block opened on line 27"},
        {"unknown bone key", with_line(a, 18, "    nmae a"), m, "tiny.asf", 18,
         "expected id, name, direction, length, axis, dof, limits or end"},
        {"bad dof", with_line(a, 22, "    dof rx ry rq"), m, "tiny.asf", 22, "expected a dof (rx, ry or rz), found 'rq'"},
        {"translation dof", with_line(a, 22, "    dof rx tx ry"), m, "tiny.asf", 22, "'tx' is not supported"},
        {"dof twice", with_line(a, 22, "    dof rx rx rz"), m, "tiny.asf", 22, "listed twice"},
        {"short direction", with_line(a, 19, "    direction 0 1"), m, "tiny.asf", 19, "needs 3 numbers"},
        {"nan direction", with_line(a, 19, "    direction 0 nan 0"), m, "tiny.asf", 19,
         "expected a finite number for bone direction, found 'nan'"},
        {"zero direction", with_line(a, 19, "    direction 0 0 0"), m, "tiny.asf", 19, "zero direction"},
        {"inf length", with_line(a, 20, "    length inf"), m, "tiny.asf", 20, "expected a finite number for bone length"},
        {"huge length", with_line(a, 20, "    length 1e300"), m, "tiny.asf", 20, "out of range"},
        {"overflowing length", with_line(a, 20, "    length 1" + std::string(400, '0')), m, "tiny.asf", 20,
         "out of range"},
        {"word length", with_line(a, 20, "    length abc"), m, "tiny.asf", 20,
         "expected a finite number for bone length, found 'abc'"},
        {"negative length", with_line(a, 20, "    length -2"), m, "tiny.asf", 20, "must not be negative"},
        {"id not a number", with_line(a, 17, "    id one"), m, "tiny.asf", 17, "expected a whole number after 'id'"},
        {"bad axis order", with_line(a, 21, "    axis 0 0 0 XYW"), m, "tiny.asf", 21, "expected an axis order"},
        {"missing axis", with_line(a, 21, ""), m, "tiny.asf", 26, "lacks 'axis'"},
        {"too few limits", with_line(a, 25, ""), m, "tiny.asf", 23, "has 3 dofs but 2 limit pairs"},
        {"too many limits", with_line(a, 25, "           (-180 180) (0 1)"), m, "tiny.asf", 23,
         "has 3 dofs but 4 limit pairs"},
        {"unclosed limit", with_line(a, 24, "           (-180 180"), m, "tiny.asf", 24, "expected ')'"},
        {"limit not a number", with_line(a, 24, "           (-180 x)"), m, "tiny.asf", 24,
         "expected a finite number for upper limit"},
        {"stray limit line", with_line(a, 33, "    (0 1)"), m, "tiny.asf", 33, "must continue 'limits'"},
        {"duplicate bone", with_line(a, 29, "    name a"), m, "tiny.asf", 29,
         "duplicate bone name 'a' (first defined on line 18)"},
        {"bone named root", with_line(a, 29, "    name root"), m, "tiny.asf", 29, "cannot be named 'root'"},
        {"unknown child", with_line(a, 39, "    a c"), m, "tiny.asf", 39, "unknown bone 'c' in :hierarchy"},
        {"unknown parent", with_line(a, 39, "    x b"), m, "tiny.asf", 39, "unknown bone 'x' in :hierarchy"},
        {"two parents", with_line(a, 38, "    root a b"), m, "tiny.asf", 39, "'b' already has a parent (line 38)"},
        {"own parent", with_line(a, 39, "    b b"), m, "tiny.asf", 39, "cannot be its own parent"},
        {"root as child", with_line(a, 39, "    a root"), m, "tiny.asf", 39, "the root cannot be a child"},
        {"cycle", cycle, m, "tiny.asf", 40, "'a' is not reachable from root: its parents form a cycle"},
        {"unattached bone", with_line(a, 39, ""), m, "tiny.asf", 29, "'b' is not attached"},
        {"hierarchy without end", first_lines(a, 39), m, "tiny.asf", 39,
         "expected 'end' to close the :hierarchy block opened on line 37, found end of file"},
        {"hierarchy without begin", with_line(a, 37, "    root a"), m, "tiny.asf", 37, "expected 'begin' after :hierarchy"},
        {"missing hierarchy", first_lines(a, 35), m, "tiny.asf", 35, "expected a ':hierarchy' section"},
        {"missing bonedata", no_bonedata, m, "tiny.asf", 40, "expected a ':bonedata' section"},
        {"text between bones", with_line(a, 27, "  hello"), m, "tiny.asf", 27, "expected 'begin' to start a bone block"},
        {"bad root channel", with_line(a, 11, "  order TX TY TW RX RY RZ"), m, "tiny.asf", 11,
         "expected a root channel (TX, TY, TZ, RX, RY or RZ), found 'TW'"},
        {"root channel twice", with_line(a, 11, "  order TX TX TZ RX RY RZ"), m, "tiny.asf", 11, "listed twice"},
        {"bad root axis", with_line(a, 12, "  axis XXY"), m, "tiny.asf", 12, "expected an axis order such as XYZ"},
        {"root lacks position", with_line(a, 13, ""), m, "tiny.asf", 10, ":root section lacks 'position'"},
        {"unknown root key", with_line(a, 13, "  positoin 0 0 0"), m, "tiny.asf", 13,
         "expected order, axis, position or orientation"},
        {"bad angle unit", with_line(a, 7, "  angle grad"), m, "tiny.asf", 7, "expected 'deg' or 'rad'"},
        {"zero length unit", with_line(a, 6, "  length 0"), m, "tiny.asf", 6, "must be positive"},
        {"second bonedata", with_line(a, 36, ":bonedata"), m, "tiny.asf", 36,
         "second :bonedata section (the first is on line 15)"},
        {"text after :root", with_line(a, 10, ":root now"), m, "tiny.asf", 10, "expected nothing after :root"},
        {"100000-deep hierarchy", chain_asf(100000), m, "tiny.asf", chain_begin_line(1023), "too many bones"},
    };
    for (const BadCase& c : cases) check_bad(c);
}

TEST_CASE("malformed AMC files fail with file, line and what was expected", "[asf_amc]") {
    const std::string& a = kTinyAsf;
    const std::string& m = kTinyAmc;
    std::string no_dofs = with_line(a, 11, "  order");
    for (int n : {22, 23, 24, 25, 33, 34}) no_dofs = with_line(no_dofs, n, "");
    const BadCase cases[] = {
        {"empty", a, "", "tiny.amc", 1, "expected frame number 1, found end of file"},
        {"header only", a, first_lines(m, 3), "tiny.amc", 3, "expected frame number 1, found end of file"},
        {"binary", a, std::string("\x01\x02\x00\xff", 4), "tiny.amc", 1, "control byte 0x01"},
        {"starts at 0", a, with_line(m, 4, "0"), "tiny.amc", 4, "expected frame number 1, found '0'"},
        {"bone before frame 1", a, with_line(m, 4, "root 1 2 3 4 5 6"), "tiny.amc", 4,
         "expected frame number 1, found 'root'"},
        {"fractional frame", a, with_line(m, 4, "1.5"), "tiny.amc", 4, "expected frame number 1, found '1.5'"},
        {"gap", a, with_line(m, 8, "3"), "tiny.amc", 8, "expected frame number 2, found '3'"},
        {"unknown bone", a, with_line(m, 6, "c 0 0 90"), "tiny.amc", 6, "unknown bone 'c' in frame 1"},
        {"too few root values", a, with_line(m, 5, "root 10 0 0 0 0"), "tiny.amc", 5,
         "bone 'root' has 5 values in frame 1, expected 6 (tx ty tz rx ry rz)"},
        {"too many values", a, with_line(m, 7, "b 90 1"), "tiny.amc", 7, "has 2 values in frame 1, expected 1 (rx)"},
        {"word value", a, with_line(m, 6, "a 0 x 90"), "tiny.amc", 6,
         "expected a finite number for value 2 of bone 'a', found 'x'"},
        {"nan value", a, with_line(m, 10, "a 0 nan 90"), "tiny.amc", 10, "expected a finite number"},
        {"inf value", a, with_line(m, 9, "root inf 0 0 0 0 0"), "tiny.amc", 9, "expected a finite number"},
        {"huge value", a, with_line(m, 6, "a 0 1e400 90"), "tiny.amc", 6, "out of range"},
        {"missing bone", a, with_line(m, 10, ""), "tiny.amc", 8, "frame 2 has no line for bone 'a'"},
        {"bone twice", a, with_line(m, 11, "a 0 0 0"), "tiny.amc", 11, "bone 'a' is listed twice in frame 2"},
        {"truncated last frame", a, first_lines(m, 13), "tiny.amc", 12, "frame 3 has no line for bone 'a'"},
        {"header after frames", a, with_line(m, 12, ":RADIANS"), "tiny.amc", 12, "header keywords go before"},
        {"no dofs anywhere", no_dofs, "1\n", "tiny.amc", 1, "no bone of the ASF skeleton has dofs"},
        {"asf error comes first", with_line(a, 20, "    length x"), "", "tiny.asf", 20, "bone length"},
    };
    for (const BadCase& c : cases) check_bad(c);
}

TEST_CASE("load_asf_amc_files reports unreadable files", "[asf_amc]") {
    try {
        load_asf_amc_files("/nonexistent/x.asf", "/nonexistent/x.amc");
        FAIL("no ImportError");
    } catch (const ImportError& e) {
        CHECK(e.file() == "/nonexistent/x.asf");
        CHECK(e.line() == 0);
        CHECK_THAT(e.message(), Catch::Contains("cannot open"));
    }
}
