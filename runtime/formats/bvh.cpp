#include "runtime/formats/bvh.hpp"

// BVH import and export.
//
// Reading is a single forward pass over the text with an explicit stack for the
// nested joint blocks (no recursion, so a hostile 100000-deep file cannot blow
// the call stack). The hierarchy is read token by token, except that OFFSET,
// CHANNELS and the joint name must sit on the keyword's own line (every writer
// does this, and it lets "OFFSET 1 2" be reported as "needs 3 numbers" instead
// of as a confusing error on the next line). The MOTION section is read line by
// line: one frame per line, exactly one value per channel.
//
// Decisions:
// - More than one ROOT is accepted: each extra root becomes a joint with parent
//   kNoParent (the Skeleton supports several roots).
// - Limits: at most kMaxJoints joints, 0..6 channels per joint (each channel at
//   most once), Frames >= 1, Frames × joints <= kMaxPoseSamples, |value| <=
//   kMaxTextNumber (runtime/formats/text_number.hpp), Frame Time in [kMinFrameTime, inf). Every limit is checked
//   before anything is allocated from it, and Frames is first checked against
//   the bytes that actually follow (each value needs at least one character and
//   a separator).
// - Control bytes other than whitespace are rejected up front: that is how
//   binary files are recognised, with the line where the first one sits.

#include <array>
#include <charconv>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <system_error>
#include <unordered_map>
#include <vector>

#include "runtime/formats/file_names.hpp"
#include "runtime/formats/text_lexer.hpp"
#include "runtime/formats/text_number.hpp"

namespace marionette {

namespace {

using namespace text;

constexpr int kMaxJoints = 1024;
constexpr int kMaxChannelsPerJoint = 6;
// Frames × joints; 2^24 pose samples is about 470 MB of quaternions and vectors,
// far beyond any real capture (10 minutes at 120 Hz of 200 joints is 14.4M).
constexpr std::int64_t kMaxPoseSamples = std::int64_t{1} << 24;
// One megahertz: anything faster is not a frame time.
constexpr double kMinFrameTime = 1.0e-6;
// When both matrix entries that give the Z angle of a Z·X·Y decomposition are
// below this, X is ±90° (gimbal lock) and Z is set to 0 so Y takes the whole
// twist. Float quaternions carry ~1e-7 of noise, so a smaller threshold would
// leave Z at the mercy of that noise; ignoring entries this small costs at most
// ~1.5e-7 rad, far inside the 1e-4° round-trip promise.
constexpr double kGimbalEpsilon = 1.0e-7;
// Significant digits for angles in degrees: 9 keeps the round-trip error below
// 1e-6 degrees, well under the 1e-4 the header promises.
constexpr int kAngleDigits = 9;

std::string found(const Token* token) { return token ? ", found " + quote_token(token->text) : ", found end of file"; }

// ---------------------------------------------------------------- hierarchy

enum class Channel : std::uint8_t { x_position, y_position, z_position, x_rotation, y_rotation, z_rotation };

constexpr std::array<std::string_view, 6> kChannelNames = {"Xposition", "Yposition", "Zposition",
                                                           "Xrotation", "Yrotation", "Zrotation"};

bool is_position(Channel c) { return c <= Channel::z_position; }
int axis_of(Channel c) { return static_cast<int>(c) % 3; }

struct JointChannels {
    std::array<Channel, kMaxChannelsPerJoint> list{};
    int count = 0;
    int first_value = 0;  // index of this joint's first value on a frame line
    bool has_position = false;
};

// A '{' block being read: a joint, or (joint < 0) an End Site.
struct OpenBlock {
    int joint = -1;
    int open_line = 0;
    bool has_offset = false;
    bool has_channels = false;
    bool has_children = false;
    vec3 offset{0.0f};
};

struct Hierarchy {
    Skeleton skeleton;
    std::vector<JointChannels> channels;
    int total_channels = 0;
};

std::string block_name(const Hierarchy& h, const OpenBlock& block) {
    if (block.joint < 0) return "End Site";
    return "joint " + quote_token(h.skeleton.joint_names[static_cast<std::size_t>(block.joint)]);
}

// The values after a keyword, all on its line.
vec3 read_offset(TextLexer& cur, const Token& keyword) {
    std::array<double, 3> v{};
    int count = 0;
    Token t;
    while (cur.next_token_on_line(t)) {
        if (count < 3) {
            const NumberStatus status = parse_real(t.text, v[static_cast<std::size_t>(count)]);
            if (status == NumberStatus::too_large)
                cur.fail(t.line, "OFFSET value " + quote_token(t.text) + " is out of range (expected a magnitude up to 1e9)");
            if (status != NumberStatus::ok)
                cur.fail(t.line, "expected a finite number in OFFSET" + found(&t));
        }
        ++count;
    }
    if (count != 3)
        cur.fail(keyword.line, "OFFSET needs 3 numbers on its line, found " + std::to_string(count));
    return vec3(static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]));
}

JointChannels read_channels(TextLexer& cur, const Token& keyword) {
    Token t;
    if (!cur.next_token_on_line(t)) cur.fail(keyword.line, "expected the channel count after CHANNELS, found end of line");
    std::int64_t declared = 0;
    if (!parse_integer(t.text, declared))
        cur.fail(t.line, "expected the channel count after CHANNELS" + found(&t));
    if (declared < 0 || declared > kMaxChannelsPerJoint)
        cur.fail(t.line, "CHANNELS count must be 0 to 6, found " + quote_token(t.text));
    JointChannels jc;
    int listed = 0;
    while (cur.next_token_on_line(t)) {
        ++listed;
        if (listed > declared) continue;  // counted for the message below
        int which = -1;
        for (std::size_t i = 0; i < kChannelNames.size(); ++i)
            if (iequals(t.text, kChannelNames[i])) which = static_cast<int>(i);
        if (which < 0)
            cur.fail(t.line, "expected a channel name (Xposition, Yposition, Zposition, Xrotation, Yrotation or "
                             "Zrotation)" + found(&t));
        const auto channel = static_cast<Channel>(which);
        for (int i = 0; i < jc.count; ++i)
            if (jc.list[static_cast<std::size_t>(i)] == channel)
                cur.fail(t.line, "channel " + quote_token(t.text) + " is listed twice in one CHANNELS line");
        jc.list[static_cast<std::size_t>(jc.count++)] = channel;
        if (is_position(channel)) jc.has_position = true;
    }
    if (listed != declared)
        cur.fail(keyword.line, "CHANNELS " + std::to_string(declared) + " expects " + std::to_string(declared) +
                                   " channel names on its line, found " + std::to_string(listed));
    return jc;
}

// After ROOT/JOINT: the name, then '{' (on the same line or the next).
void open_joint(TextLexer& cur, Hierarchy& h, std::vector<OpenBlock>& stack,
                std::unordered_map<std::string_view, int>& name_lines, const Token& keyword, int parent) {
    Token name;
    if (!cur.next_token_on_line(name) || name.text.find_first_of("{}") != std::string_view::npos)
        cur.fail(keyword.line, "expected a joint name (one word) after " + std::string(keyword.text));
    if (h.skeleton.joint_count() >= kMaxJoints)
        cur.fail(name.line, "too many joints: more than " + std::to_string(kMaxJoints) + " (the limit)");
    const auto [it, inserted] = name_lines.emplace(name.text, name.line);
    if (!inserted)
        cur.fail(name.line, "duplicate joint name " + quote_token(name.text) + " (first used on line " +
                                std::to_string(it->second) + ")");
    Token brace;
    if (cur.next_token_on_line(brace)) {
        if (brace.text != "{")
            cur.fail(brace.line, "expected '{' after joint " + quote_token(name.text) + " (names are one word)" + found(&brace));
        Token extra;
        if (cur.next_token_on_line(extra)) cur.fail(extra.line, "expected end of line after '{'" + found(&extra));
    } else {
        const bool have = cur.next_token(brace);
        if (!have || brace.text != "{")
            cur.fail(have ? brace.line : cur.end_line(), "expected '{' after joint " + quote_token(name.text) +
                                                         found(have ? &brace : nullptr));
    }
    h.skeleton.joint_names.emplace_back(name.text);
    h.skeleton.parents.push_back(parent);
    h.skeleton.rest_offsets.push_back(vec3(0.0f));
    h.channels.push_back(JointChannels{});
    OpenBlock block;
    block.joint = h.skeleton.joint_count() - 1;
    block.open_line = brace.line;
    stack.push_back(block);
}

// Reads from after "HIERARCHY" up to and including the MOTION keyword.
Hierarchy read_hierarchy(TextLexer& cur) {
    Hierarchy h;
    std::vector<OpenBlock> stack;
    std::unordered_map<std::string_view, int> name_lines;
    Token t;
    for (;;) {
        const bool have = cur.next_token(t);
        if (stack.empty()) {
            if (!have)
                cur.fail(cur.end_line(), h.skeleton.joint_count() == 0 ? "expected ROOT, found end of file"
                                                                   : "expected MOTION section, found end of file");
            if (iequals(t.text, "ROOT")) {
                open_joint(cur, h, stack, name_lines, t, kNoParent);
                continue;
            }
            if (iequals(t.text, "MOTION")) {
                if (h.skeleton.joint_count() == 0) cur.fail(t.line, "expected ROOT before MOTION");
                Token extra;
                if (cur.next_token_on_line(extra)) cur.fail(extra.line, "expected end of line after MOTION" + found(&extra));
                return h;
            }
            cur.fail(t.line, std::string(h.skeleton.joint_count() == 0 ? "expected ROOT" : "expected ROOT or MOTION") +
                                 found(&t));
        }
        OpenBlock& top = stack.back();
        auto closing = [&] {
            return "expected '}' to close " + block_name(h, top) + " opened on line " + std::to_string(top.open_line);
        };
        if (!have) cur.fail(cur.end_line(), closing() + ", found end of file");
        if (iequals(t.text, "OFFSET")) {
            if (top.has_offset) cur.fail(t.line, block_name(h, top) + " has a second OFFSET");
            if (top.has_children)
                cur.fail(t.line, "OFFSET of " + block_name(h, top) + " must come before its child joints");
            top.offset = read_offset(cur, t);
            top.has_offset = true;
        } else if (iequals(t.text, "CHANNELS")) {
            if (top.joint < 0) cur.fail(t.line, "an End Site has no CHANNELS (expected OFFSET or '}')");
            if (top.has_channels) cur.fail(t.line, block_name(h, top) + " has a second CHANNELS line");
            if (top.has_children)
                cur.fail(t.line, "CHANNELS of " + block_name(h, top) + " must come before its child joints");
            JointChannels jc = read_channels(cur, t);
            jc.first_value = h.total_channels;
            h.total_channels += jc.count;
            h.channels[static_cast<std::size_t>(top.joint)] = jc;
            top.has_channels = true;
        } else if (iequals(t.text, "JOINT") || iequals(t.text, "End")) {
            if (top.joint < 0) cur.fail(t.line, "an End Site cannot contain joints (expected OFFSET or '}')");
            if (!top.has_offset) cur.fail(t.line, "expected OFFSET of " + block_name(h, top) + " before its children");
            top.has_children = true;
            const int parent = top.joint;
            if (iequals(t.text, "JOINT")) {
                open_joint(cur, h, stack, name_lines, t, parent);  // may reallocate: `top` is dead from here
            } else {
                Token site;
                if (!cur.next_token_on_line(site) || !iequals(site.text, "Site"))
                    cur.fail(t.line, "expected 'Site' after 'End'");
                Token brace;
                const bool have_brace = cur.next_token(brace);
                if (!have_brace || brace.text != "{")
                    cur.fail(have_brace ? brace.line : cur.end_line(),
                             "expected '{' after End Site" + found(have_brace ? &brace : nullptr));
                OpenBlock block;
                block.joint = -1;
                block.open_line = brace.line;
                stack.push_back(block);
            }
        } else if (t.text == "}") {
            if (!top.has_offset) cur.fail(t.line, block_name(h, top) + " closes without an OFFSET");
            if (top.joint < 0) {
                h.skeleton.end_site_parents.push_back(stack[stack.size() - 2].joint);
                h.skeleton.end_site_offsets.push_back(top.offset);
            } else {
                h.skeleton.rest_offsets[static_cast<std::size_t>(top.joint)] = top.offset;
            }
            stack.pop_back();
        } else if (iequals(t.text, "ROOT") || iequals(t.text, "MOTION")) {
            cur.fail(t.line, closing() + found(&t));
        } else {
            cur.fail(t.line, "expected OFFSET, CHANNELS, JOINT, End Site or '}' in " + block_name(h, top) + found(&t));
        }
    }
}

// ---------------------------------------------------------------- motion

// "Frames: 69", "Frames:69", "Frames 69" (any case, any blanks).
std::int64_t parse_frames_line(const TextLexer& cur, std::string_view line, int line_no) {
    std::string_view rest = trim_blanks(line);
    const char* expected = "expected 'Frames: <count>' after MOTION";
    if (!istarts_with(rest, "Frames")) cur.fail(line_no, std::string(expected) + ", found " + quote_token(rest));
    rest = trim_blanks(rest.substr(6));
    if (!rest.empty() && rest.front() == ':') rest = trim_blanks(rest.substr(1));
    std::int64_t frames = 0;
    if (!parse_integer(rest, frames))
        cur.fail(line_no, std::string(expected) + " with a whole number, found " + quote_token(rest));
    if (frames < 1) cur.fail(line_no, "Frames must be at least 1, found " + quote_token(rest));
    return frames;
}

// "Frame Time: .0083333", "Frame Time:0.033", "FrameTime 0.033" (any case).
double parse_frame_time_line(const TextLexer& cur, std::string_view line, int line_no) {
    std::string_view rest = trim_blanks(line);
    const char* expected = "expected 'Frame Time: <seconds>' after Frames";
    if (!istarts_with(rest, "Frame")) cur.fail(line_no, std::string(expected) + ", found " + quote_token(rest));
    rest = trim_blanks(rest.substr(5));
    if (!istarts_with(rest, "Time")) cur.fail(line_no, std::string(expected) + ", found " + quote_token(trim_blanks(line)));
    rest = trim_blanks(rest.substr(4));
    if (!rest.empty() && rest.front() == ':') rest = trim_blanks(rest.substr(1));
    double seconds = 0.0;
    if (parse_real(rest, seconds) != NumberStatus::ok)
        cur.fail(line_no, std::string(expected) + " with a finite number, found " + quote_token(rest));
    if (!(seconds >= kMinFrameTime))
        cur.fail(line_no, "Frame Time must be at least 1e-6 seconds, found " + quote_token(rest));
    return seconds;
}

bool is_blank_line(std::string_view line) { return trim_blanks(line).empty(); }

// One frame's local pose from its channel values.
void fill_pose(const Hierarchy& h, const std::vector<double>& values, quat* rotations, vec3* translations) {
    static const std::array<vec3, 3> kAxes = {vec3(1, 0, 0), vec3(0, 1, 0), vec3(0, 0, 1)};
    const std::size_t joints = h.channels.size();
    for (std::size_t j = 0; j < joints; ++j) {
        const JointChannels& jc = h.channels[j];
        quat q = quat_identity();
        vec3 t = h.skeleton.rest_offsets[j];
        for (int c = 0; c < jc.count; ++c) {
            const Channel channel = jc.list[static_cast<std::size_t>(c)];
            const double v = values[static_cast<std::size_t>(jc.first_value + c)];
            const int axis = axis_of(channel);
            if (is_position(channel)) {
                t[axis] = static_cast<float>(v);
            } else {
                // Listed order, column vectors: R = R1·R2·R3, so each new factor
                // multiplies on the right.
                q = quat_mul(q, quat_axis_angle(kAxes[static_cast<std::size_t>(axis)], v * det::kDegToRad));
            }
        }
        rotations[j] = quat_normalize(q);
        translations[j] = t;
    }
}

void read_motion(TextLexer& cur, const Hierarchy& h, Clip& clip) {
    std::string_view line;
    int line_no = 0;
    do {
        if (!cur.next_line(line, line_no)) cur.fail(cur.end_line(), "expected 'Frames: <count>' after MOTION, found end of file");
    } while (is_blank_line(line));
    const int frames_line = line_no;
    const std::int64_t frames = parse_frames_line(cur, line, line_no);
    do {
        if (!cur.next_line(line, line_no)) cur.fail(cur.end_line(), "expected 'Frame Time: <seconds>' after Frames, found end of file");
    } while (is_blank_line(line));
    const double frame_time = parse_frame_time_line(cur, line, line_no);

    const std::int64_t channels = h.total_channels;
    const std::int64_t joints = h.skeleton.joint_count();
    if (channels == 0) cur.fail(frames_line, "no joint has CHANNELS, so there is no motion to read");
    // Each value needs at least one character and one separator (the very last
    // one may end the file): check before trusting Frames with an allocation.
    const auto remaining = static_cast<std::int64_t>(cur.remaining());
    if (frames > (remaining + 1) / (2 * channels))
        cur.fail(frames_line, "Frames: " + std::to_string(frames) + " is more than the file can hold: " +
                                  std::to_string(frames) + " frames of " + std::to_string(channels) +
                                  " values need more than the " + std::to_string(remaining) +
                                  " bytes that follow (expected Frames to match the frame lines)");
    if (frames * joints > kMaxPoseSamples)
        cur.fail(frames_line, "Frames × joints = " + std::to_string(frames * joints) + " exceeds the limit of " +
                                  std::to_string(kMaxPoseSamples) + " pose samples");

    const auto joint_count = static_cast<std::size_t>(joints);
    clip.frame_rate = 1.0 / frame_time;
    clip.frame_count = static_cast<int>(frames);
    clip.rotations.resize(static_cast<std::size_t>(frames) * joint_count);
    clip.translations.resize(clip.rotations.size());
    std::vector<double> values(static_cast<std::size_t>(channels));
    std::int64_t frame = 0;
    while (cur.next_line(line, line_no)) {
        if (is_blank_line(line)) continue;
        if (frame == frames)
            cur.fail(line_no, "expected end of file after " + std::to_string(frames) +
                                  " frames (Frames: " + std::to_string(frames) + "), found another frame line");
        std::int64_t count = 0;
        for_each_word(line, [&](std::string_view token) {
            if (count < channels) {
                const NumberStatus status = parse_real(token, values[static_cast<std::size_t>(count)]);
                if (status == NumberStatus::too_large)
                    cur.fail(line_no, "value " + quote_token(token) + " is out of range (expected a magnitude up to 1e9)");
                if (status != NumberStatus::ok)
                    cur.fail(line_no, "expected a finite number (value " + std::to_string(count + 1) + " of frame " +
                                          std::to_string(frame + 1) + "), found " + quote_token(token));
            }
            ++count;
        });
        if (count != channels)
            cur.fail(line_no, "frame " + std::to_string(frame + 1) + " has " + std::to_string(count) +
                                  " values, expected " + std::to_string(channels) + " (one per channel)");
        const std::size_t base = static_cast<std::size_t>(frame) * joint_count;
        fill_pose(h, values, clip.rotations.data() + base, clip.translations.data() + base);
        ++frame;
    }
    if (frame < frames)
        cur.fail(cur.end_line(), "expected " + std::to_string(frames) + " frames (Frames: " + std::to_string(frames) +
                                 "), but the file ends after " + std::to_string(frame));
}

// ---------------------------------------------------------------- export

void append_float(std::string& out, float v) {
    char buf[64];
    // Shortest text that reads back as the same float: exact round trip.
    const auto result = std::to_chars(buf, buf + sizeof buf, v + 0.0f);  // + 0 turns -0 into 0
    out.append(buf, result.ptr);
}

void append_double(std::string& out, double v, int digits) {
    char buf[64];
    const auto result = std::to_chars(buf, buf + sizeof buf, v + 0.0, std::chars_format::general, digits);
    out.append(buf, result.ptr);
}

void append_shortest(std::string& out, double v) {
    char buf[64];
    const auto result = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, result.ptr);
}

// Angles (radians) z, x, y with R(q) = Rz(z)·Rx(x)·Ry(y).
//
// With c/s for cos/sin, the matrix is
//   [ cz·cy − sz·sx·sy   −sz·cx   cz·sy + sz·sx·cy ]
//   [ sz·cy + cz·sx·sy    cz·cx   sz·sy − cz·sx·cy ]
//   [ −cx·sy              sx      cx·cy            ]
// z comes from the middle column's top two entries; the remaining Rx·Ry =
// Rz(−z)·R then gives x and y from entries of magnitude cos/sin themselves, so
// nothing divides by cx and gimbal lock (cx → 0) costs no accuracy: there z is
// set to 0 and y absorbs the twist.
void euler_zxy(quat q, double& z, double& x, double& y) {
    const double w = q.w, qx = q.x, qy = q.y, qz = q.z;
    const double n2 = w * w + qx * qx + qy * qy + qz * qz;
    const double s = n2 > 0.0 ? 2.0 / n2 : 0.0;
    const double m00 = 1.0 - s * (qy * qy + qz * qz);
    const double m01 = s * (qx * qy - w * qz);
    const double m02 = s * (qx * qz + w * qy);
    const double m10 = s * (qx * qy + w * qz);
    const double m11 = 1.0 - s * (qx * qx + qz * qz);
    const double m12 = s * (qy * qz - w * qx);
    const double m21 = s * (qy * qz + w * qx);
    const bool locked = (m01 < 0 ? -m01 : m01) < kGimbalEpsilon && (m11 < 0 ? -m11 : m11) < kGimbalEpsilon;
    z = locked ? 0.0 : det::atan2(-m01, m11);
    double sz = 0.0, cz = 1.0;
    det::sin_cos(z, sz, cz);
    // Rows of Rz(−z)·R that hold x and y.
    const double r00 = cz * m00 + sz * m10;
    const double r02 = cz * m02 + sz * m12;
    const double r11 = cz * m11 - sz * m01;
    y = det::atan2(r02, r00);
    x = det::atan2(m21, r11);
}

bool valid_export_name(const std::string& name) {
    if (name.empty() || name.find_first_of("{}") != std::string::npos) return false;
    for (char c : name)
        if (is_space(c) || static_cast<unsigned char>(c) < 0x20 || c == 0x7F) return false;
    return true;
}

void check_exportable(const Clip& clip) {
    if (const Outcome valid = validate_clip(clip); !valid.ok())
        throw std::invalid_argument("export_bvh: " + valid.problem());
    for (const std::string& name : clip.skeleton.joint_names)
        if (!valid_export_name(name))
            throw std::invalid_argument("export_bvh: joint name " + quote_token(name) +
                                        " cannot be written to BVH (expected one word without braces)");
}

// Position channels for flagged joints and roots, and also for any joint whose
// translation ever leaves its rest offset: otherwise that motion would be lost,
// and the promise is that the file imports to the same poses.
std::vector<bool> joints_with_position_channels(const Clip& clip) {
    const Skeleton& sk = clip.skeleton;
    const auto joints = static_cast<std::size_t>(sk.joint_count());
    std::vector<bool> positions(joints, false);
    for (std::size_t j = 0; j < joints; ++j) positions[j] = clip.animated_translation[j] || sk.parents[j] == kNoParent;
    for (int f = 0; f < clip.frame_count; ++f) {
        const vec3* t = clip.frame_translations(f);
        for (std::size_t j = 0; j < joints; ++j)
            if (t[j] != sk.rest_offsets[j]) positions[j] = true;
    }
    return positions;
}

// Each joint's child joints and end sites, in skeleton order.
struct JointTree {
    std::vector<std::vector<int>> children;
    std::vector<std::vector<std::size_t>> end_sites;
};

JointTree joint_tree(const Skeleton& sk) {
    const auto joints = static_cast<std::size_t>(sk.joint_count());
    JointTree tree{std::vector<std::vector<int>>(joints), std::vector<std::vector<std::size_t>>(joints)};
    for (std::size_t j = 0; j < joints; ++j)
        if (sk.parents[j] != kNoParent)
            tree.children[static_cast<std::size_t>(sk.parents[j])].push_back(static_cast<int>(j));
    for (std::size_t e = 0; e < sk.end_site_parents.size(); ++e)
        tree.end_sites[static_cast<std::size_t>(sk.end_site_parents[e])].push_back(e);
    return tree;
}

void indent(std::string& out, std::size_t depth) { out.append(depth, '\t'); }

void append_offset_line(std::string& out, std::size_t depth, vec3 offset) {
    indent(out, depth);
    out += "OFFSET ";
    append_float(out, offset.x);
    out += ' ';
    append_float(out, offset.y);
    out += ' ';
    append_float(out, offset.z);
    out += '\n';
}

// "ROOT name" or "JOINT name", '{', OFFSET and CHANNELS; the '}' comes after the children.
void open_joint_block(std::string& out, const Skeleton& sk, std::size_t joint, std::size_t depth, bool position_channels) {
    indent(out, depth);
    out += sk.parents[joint] == kNoParent ? "ROOT " : "JOINT ";
    out += sk.joint_names[joint];
    out += '\n';
    indent(out, depth);
    out += "{\n";
    append_offset_line(out, depth + 1, sk.rest_offsets[joint]);
    indent(out, depth + 1);
    out += position_channels ? "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
                             : "CHANNELS 3 Zrotation Xrotation Yrotation\n";
}

void write_end_site(std::string& out, std::size_t depth, vec3 offset) {
    indent(out, depth);
    out += "End Site\n";
    indent(out, depth);
    out += "{\n";
    append_offset_line(out, depth + 1, offset);
    indent(out, depth);
    out += "}\n";
}

// The HIERARCHY section, depth-first without recursion. Returns the joints in
// the order written, which is the channel order.
std::vector<int> write_hierarchy(std::string& out, const Skeleton& sk, const std::vector<bool>& positions) {
    const auto joints = static_cast<std::size_t>(sk.joint_count());
    const JointTree tree = joint_tree(sk);
    out += "HIERARCHY\n";
    std::vector<int> order;
    order.reserve(joints);
    struct Frame {
        int joint;
        std::size_t next_child;
    };
    std::vector<Frame> stack;
    auto open = [&](int j, std::size_t depth) {
        const auto ju = static_cast<std::size_t>(j);
        open_joint_block(out, sk, ju, depth, positions[ju]);
        order.push_back(j);
        stack.push_back({j, 0});
    };
    for (std::size_t root = 0; root < joints; ++root) {
        if (sk.parents[root] != kNoParent) continue;
        open(static_cast<int>(root), 0);
        while (!stack.empty()) {
            Frame& top = stack.back();
            const auto ju = static_cast<std::size_t>(top.joint);
            const std::size_t depth = stack.size() - 1;
            if (top.next_child < tree.children[ju].size()) {
                const int child = tree.children[ju][top.next_child++];
                open(child, depth + 1);  // may reallocate: `top` is dead from here
                continue;
            }
            for (std::size_t e : tree.end_sites[ju]) write_end_site(out, depth + 1, sk.end_site_offsets[e]);
            indent(out, depth);
            out += "}\n";
            stack.pop_back();
        }
    }
    return order;
}

// The MOTION section: per frame, each joint in `order` as its positions (if
// it has position channels) then Z, X, Y angles in degrees.
void write_motion(std::string& out, const Clip& clip, const std::vector<bool>& positions, const std::vector<int>& order) {
    out += "MOTION\nFrames: ";
    out += std::to_string(clip.frame_count);
    out += "\nFrame Time: ";
    append_shortest(out, 1.0 / clip.frame_rate);
    out += '\n';
    for (int f = 0; f < clip.frame_count; ++f) {
        const quat* r = clip.frame_rotations(f);
        const vec3* t = clip.frame_translations(f);
        bool first = true;
        auto separator = [&] {
            if (!first) out += ' ';
            first = false;
        };
        for (int j : order) {
            const auto ju = static_cast<std::size_t>(j);
            if (positions[ju]) {
                for (int axis = 0; axis < 3; ++axis) {
                    separator();
                    append_float(out, t[ju][axis]);
                }
            }
            double z = 0.0, x = 0.0, y = 0.0;
            euler_zxy(r[ju], z, x, y);
            for (double angle : {z, x, y}) {
                separator();
                append_double(out, angle * det::kRadToDeg, kAngleDigits);
            }
        }
        out += '\n';
    }
}

}  // namespace

Clip import_bvh(std::string_view text, const std::string& file_name) {
    TextLexer cur(text, file_name);
    cur.reject_control_bytes("BVH");
    cur.skip_utf8_bom();
    Token first;
    const bool have = cur.next_token(first);
    if (!have || !iequals(first.text, "HIERARCHY"))
        cur.fail(have ? first.line : cur.end_line(),
                 "expected 'HIERARCHY' at the start of a BVH file" + found(have ? &first : nullptr));
    const Hierarchy h = read_hierarchy(cur);

    Clip clip;
    clip.name = clip_name_from_path(file_name);
    clip.skeleton = h.skeleton;
    clip.length_unit = 1.0;
    clip.animated_translation.resize(h.channels.size());
    for (std::size_t j = 0; j < h.channels.size(); ++j) clip.animated_translation[j] = h.channels[j].has_position;
    read_motion(cur, h, clip);
    // Holds by construction; kept as a guard so a parser bug surfaces as an
    // error rather than as a clip that breaks its users.
    if (const Outcome valid = validate_clip(clip); !valid.ok()) cur.fail(0, "inconsistent clip: " + valid.problem());
    return clip;
}

Clip load_bvh_file(const std::string& path) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        throw ImportError(path, 0, "is a directory, expected a BVH file");
    errno = 0;
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        const int err = errno;  // set by the failed open
        throw ImportError(path, 0, "cannot open the file for reading" +
                                       (err ? ": " + std::generic_category().message(err) : std::string()));
    }
    const std::string text = read_capped_text(in, path, "a BVH clip");
    return import_bvh(text, path);
}

std::string export_bvh(const Clip& clip) {
    check_exportable(clip);
    const std::vector<bool> positions = joints_with_position_channels(clip);
    std::string out;
    const std::vector<int> order = write_hierarchy(out, clip.skeleton, positions);
    write_motion(out, clip, positions, order);
    return out;
}

}  // namespace marionette
