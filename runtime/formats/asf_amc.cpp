#include "runtime/formats/asf_amc.hpp"

// Acclaim ASF/AMC import.
//
// Geometry. The Acclaim model gives every bone b an axis frame C_b (from
// `axis a b c XYZ`, a rotation relative to the global frame) and a motion M_b
// built from the AMC values of its dofs; the bone's world rotation is
//     W_b = W_parent · C_b · M_b · C_b⁻¹
// and its end is the parent's end plus W_b · (direction_b · length_b), where
// `direction` is given in global coordinates. Here the joint of bone b sits at
// the bone's start and takes
//     local rotation  L_b = C_b · M_b · C_b⁻¹
//     rest offset     = direction_p · length_p of the parent bone p (0 for the
//                       root's children, which start at the root)
// so the rest pose has identity local rotations, every joint frame coincides
// with the global frame at rest, and offsets written in global coordinates are
// already in the parent joint's frame. The FK chain R_b = R_parent · L_b then
// reproduces W_b exactly, and position_child = position_b + R_b · offset is the
// Acclaim bone end. The root works the same way with C from `:root axis` +
// `orientation`; its translation channels replace the matching components of
// the rest offset (`:root position`), like BVH position channels.
//
// Euler angles. `axis 10 20 30 XYZ` lists the angles about x, y and z in that
// order and applies them in the order named (X first): C = Rz·Ry·Rx on column
// vectors. A dof list `rx ry rz` (and the root `order`) applies its rotations
// in the order listed, first listed first: M = Rz·Ry·Rx. This is what the CMU
// readers compute for the CMU files (where every list is in x, y, z order).
//
// Decisions:
// - Directions are normalised (the format says unit vector; the files round
//   to six digits), so FK bone lengths equal `length` exactly. A zero direction
//   is refused unless the length is zero.
// - Only rx/ry/rz dofs are read; tx/ty/tz/l are refused, since only the root's
//   translation is animated in this runtime.
// - `:units angle` sets the unit for the ASF and, unless the AMC says
//   `:DEGREES` or `:RADIANS` before its first frame, for the AMC.
// - Joints are ordered depth-first from the root, children in the order the
//   hierarchy lists them (as the CMU BVH conversions do), without recursion.
// - AMC frames must be numbered 1, 2, 3, ... and list every bone that has
//   dofs exactly once with exactly one value per dof.
// - Limits: at most kMaxBones bones, |number| <= kMaxTextNumber (runtime/formats/text_number.hpp), frames ×
//   joints <= kMaxPoseSamples; frames are stored as they are read, so no
//   allocation is sized by a number from the file.
// - Control bytes other than whitespace are refused up front (binary files).

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <unordered_map>
#include <utility>
#include <vector>

#include "runtime/formats/file_names.hpp"
#include "runtime/formats/text_lexer.hpp"
#include "runtime/formats/text_number.hpp"

namespace marionette {

// The parsed ASF: the skeleton plus what reading an AMC against it needs.
struct AsfSkeleton {
    struct Dofs {
        // Channel codes: 0..2 translate along x, y, z; 3..5 rotate about x, y, z.
        std::array<std::uint8_t, 6> channels{};
        int count = 0;
        quat axis = quat_identity();  // C: the bone's axis frame
    };
    Skeleton skeleton;
    std::vector<Dofs> dofs;  // one per joint, skeleton order
    double length_unit = 1.0;
    bool degrees = true;
};

namespace {

using namespace text;

constexpr int kMaxBones = 1023;  // plus the root: the BVH importer's 1024 joints
constexpr std::int64_t kMaxPoseSamples = std::int64_t{1} << 24;
// Shorter directions carry no usable orientation.
constexpr double kMinDirectionNorm = 1.0e-12;

constexpr std::uint8_t kRotateX = 3;

// ---------------------------------------------------------------- numbers

double read_number(const TextLexer& reader, int line, std::string_view token, const std::string& what) {
    double value = 0.0;
    switch (parse_real(token, value)) {
        case NumberStatus::ok:
            return value;
        case NumberStatus::too_large:
            reader.fail(line, what + " is out of range: " + quote_token(token) + " (expected a magnitude up to 1e9)");
        default:
            reader.fail(line, "expected a finite number for " + what + ", found " + quote_token(token));
    }
}

// The numbers after a keyword, all on its line.
std::array<double, 3> read_three(const TextLexer& reader, const Line& line,
                                 const std::vector<std::string_view>& tokens, const std::string& what) {
    if (tokens.size() != 4)
        reader.fail(line.number, quote_token(tokens[0]) + " needs 3 numbers (" + what + "), found " +
                                     std::to_string(tokens.size() - 1));
    std::array<double, 3> out{};
    for (std::size_t i = 0; i < 3; ++i) out[i] = read_number(reader, line.number, tokens[i + 1], what);
    return out;
}

// ---------------------------------------------------------------- rotations

quat axis_rotation(int axis, double radians) {
    static const std::array<vec3, 3> kAxes = {vec3(1, 0, 0), vec3(0, 1, 0), vec3(0, 0, 1)};
    return quat_axis_angle(kAxes[static_cast<std::size_t>(axis)], radians);
}

// Angles about x, y, z applied in `order` (first entry first), so for XYZ the
// result is Rz·Ry·Rx.
quat euler_rotation(const std::array<double, 3>& radians_xyz, const std::array<int, 3>& order) {
    quat q = quat_identity();
    for (int axis : order) q = quat_mul(axis_rotation(axis, radians_xyz[static_cast<std::size_t>(axis)]), q);
    return quat_normalize(q);
}

// "XYZ", "zyx", ...: each axis exactly once.
bool parse_axis_order(std::string_view token, std::array<int, 3>& order) {
    if (token.size() != 3) return false;
    bool used[3] = {false, false, false};
    for (std::size_t i = 0; i < 3; ++i) {
        const char c = ascii_lower(token[i]);
        if (c < 'x' || c > 'z' || used[c - 'x']) return false;
        used[c - 'x'] = true;
        order[i] = c - 'x';
    }
    return true;
}

// ---------------------------------------------------------------- ASF

struct BoneDef {
    std::string_view name;
    int begin_line = 0;
    int name_line = 0;
    int direction_line = 0;
    int length_line = 0;
    int axis_line = 0;
    int dof_line = 0;
    int limits_line = 0;
    bool has_id = false;
    int limit_pairs = 0;
    std::array<double, 3> direction{};
    double length = 0.0;
    std::array<double, 3> axis{};
    std::array<int, 3> axis_order{0, 1, 2};
    AsfSkeleton::Dofs dofs;
};

struct RootDef {
    int line = 0;
    int order_line = 0;
    int axis_line = 0;
    int position_line = 0;
    int orientation_line = 0;
    AsfSkeleton::Dofs dofs;
    std::array<int, 3> axis_order{0, 1, 2};
    std::array<double, 3> position{};
    std::array<double, 3> orientation{};
};

struct HierarchyLine {
    int line = 0;
    std::vector<std::string_view> names;  // parent, then children
};

struct AsfFile {
    double length_unit = 1.0;
    bool degrees = true;
    RootDef root;
    std::vector<BoneDef> bones;
    std::vector<HierarchyLine> hierarchy;
    int bonedata_line = 0;
    int hierarchy_line = 0;
};

bool is_section_line(const Line& line) { return line.text.front() == ':'; }

void read_units(TextLexer& reader, AsfFile& asf, std::vector<std::string_view>& tokens) {
    Line line;
    while (reader.peek_content_line(line) && !is_section_line(line)) {
        reader.next_content_line(line);
        split_blanks(line.text, tokens);
        if (tokens.size() != 2)
            reader.fail(line.number, "expected 'KEY VALUE' in :units (mass, length or angle), found " + quote_token(line.text));
        if (iequals(tokens[0], "length")) {
            const double v = read_number(reader, line.number, tokens[1], "the length unit");
            if (!(v > 0.0)) reader.fail(line.number, "the length unit must be positive, found " + quote_token(tokens[1]));
            asf.length_unit = v;
        } else if (iequals(tokens[0], "angle")) {
            const std::string_view u = tokens[1];
            if (iequals(u, "deg") || iequals(u, "degree") || iequals(u, "degrees")) {
                asf.degrees = true;
            } else if (iequals(u, "rad") || iequals(u, "radian") || iequals(u, "radians")) {
                asf.degrees = false;
            } else {
                reader.fail(line.number, "expected 'deg' or 'rad' for the angle unit, found " + quote_token(u));
            }
        } else if (iequals(tokens[0], "mass")) {
            read_number(reader, line.number, tokens[1], "the mass unit");  // checked, not used
        }
        // Other keys carry nothing this runtime uses; a 'KEY VALUE' pair is tolerated.
    }
}

void skip_section_body(TextLexer& reader) {
    Line line;
    while (reader.peek_content_line(line) && !is_section_line(line)) reader.next_content_line(line);
}

void read_root(TextLexer& reader, AsfFile& asf, std::vector<std::string_view>& tokens) {
    RootDef& root = asf.root;
    Line line;
    while (reader.peek_content_line(line) && !is_section_line(line)) {
        reader.next_content_line(line);
        split_blanks(line.text, tokens);
        const std::string_view key = tokens[0];
        auto once = [&](int& seen) {
            if (seen)
                reader.fail(line.number, ":root has a second " + quote_token(key) + " (first on line " +
                                             std::to_string(seen) + ")");
            seen = line.number;
        };
        if (iequals(key, "order")) {
            once(root.order_line);
            if (tokens.size() > 7)
                reader.fail(line.number, "root order lists " + std::to_string(tokens.size() - 1) +
                                             " channels, expected at most 6 (TX TY TZ RX RY RZ)");
            for (std::size_t i = 1; i < tokens.size(); ++i) {
                const std::string_view t = tokens[i];
                if (t.size() != 2 || (ascii_lower(t[0]) != 't' && ascii_lower(t[0]) != 'r') ||
                    ascii_lower(t[1]) < 'x' || ascii_lower(t[1]) > 'z')
                    reader.fail(line.number, "expected a root channel (TX, TY, TZ, RX, RY or RZ), found " + quote_token(t));
                const auto code = static_cast<std::uint8_t>((ascii_lower(t[0]) == 'r' ? 3 : 0) + (ascii_lower(t[1]) - 'x'));
                for (int c = 0; c < root.dofs.count; ++c)
                    if (root.dofs.channels[static_cast<std::size_t>(c)] == code)
                        reader.fail(line.number, "root channel " + quote_token(t) + " is listed twice in 'order'");
                root.dofs.channels[static_cast<std::size_t>(root.dofs.count++)] = code;
            }
        } else if (iequals(key, "axis")) {
            once(root.axis_line);
            if (tokens.size() != 2 || !parse_axis_order(tokens[1], root.axis_order))
                reader.fail(line.number, "expected an axis order such as XYZ after 'axis' in :root, found " +
                                             quote_token(trim_blanks(line.text.substr(4))));
        } else if (iequals(key, "position")) {
            once(root.position_line);
            root.position = read_three(reader, line, tokens, "root position");
        } else if (iequals(key, "orientation")) {
            once(root.orientation_line);
            root.orientation = read_three(reader, line, tokens, "root orientation");
        } else {
            reader.fail(line.number, "expected order, axis, position or orientation in :root, found " + quote_token(key));
        }
    }
    const std::pair<int, const char*> required[] = {{root.order_line, "order"},
                                                    {root.axis_line, "axis"},
                                                    {root.position_line, "position"},
                                                    {root.orientation_line, "orientation"}};
    for (const auto& [seen, name] : required)
        if (!seen) reader.fail(root.line, ":root section lacks '" + std::string(name) + "'");
}

// "(lo hi)" pairs; parentheses may touch the numbers or not. Infinite limits
// are part of the format ("(-inf inf)"), so they are accepted here only.
void read_limit_pairs(const TextLexer& reader, int line_no, std::string_view text, BoneDef& bone) {
    std::size_t pos = 0;
    auto skip = [&] {
        while (pos < text.size() && is_blank(text[pos])) ++pos;
    };
    auto number = [&](const char* which) {
        skip();
        const std::size_t start = pos;
        while (pos < text.size() && !is_blank(text[pos]) && text[pos] != '(' && text[pos] != ')') ++pos;
        const std::string_view token = text.substr(start, pos - start);
        if (token.empty())
            reader.fail(line_no, std::string("expected the ") + which + " limit in '(lo hi)', found " +
                                     (pos < text.size() ? quote_token(text.substr(pos, 1)) : "end of line"));
        std::string_view body = token;
        if (!body.empty() && (body.front() == '-' || body.front() == '+')) body.remove_prefix(1);
        if (iequals(body, "inf") || iequals(body, "infinity")) return;
        read_number(reader, line_no, token, std::string(which) + " limit");
    };
    for (;;) {
        skip();
        if (pos == text.size()) return;
        if (text[pos] != '(')
            reader.fail(line_no, "expected '(' to start a limit pair '(lo hi)', found " + quote_token(text.substr(pos)));
        ++pos;
        number("lower");
        number("upper");
        skip();
        if (pos == text.size() || text[pos] != ')')
            reader.fail(line_no, "expected ')' to close a limit pair '(lo hi)', found " +
                                     (pos < text.size() ? quote_token(text.substr(pos)) : std::string("end of line")));
        ++pos;
        ++bone.limit_pairs;
    }
}

void read_dofs(const TextLexer& reader, const Line& line, const std::vector<std::string_view>& tokens, BoneDef& bone) {
    if (tokens.size() < 2) reader.fail(line.number, "expected rx, ry or rz after 'dof'");
    for (std::size_t i = 1; i < tokens.size(); ++i) {
        const std::string_view t = tokens[i];
        if (iequals(t, "tx") || iequals(t, "ty") || iequals(t, "tz") || iequals(t, "l"))
            reader.fail(line.number, "dof " + quote_token(t) + " is not supported (expected rx, ry or rz; only the root "
                                     "translates)");
        if (t.size() != 2 || ascii_lower(t[0]) != 'r' || ascii_lower(t[1]) < 'x' || ascii_lower(t[1]) > 'z')
            reader.fail(line.number, "expected a dof (rx, ry or rz), found " + quote_token(t));
        const auto code = static_cast<std::uint8_t>(kRotateX + (ascii_lower(t[1]) - 'x'));
        for (int c = 0; c < bone.dofs.count; ++c)
            if (bone.dofs.channels[static_cast<std::size_t>(c)] == code)
                reader.fail(line.number, "dof " + quote_token(t) + " is listed twice");
        if (bone.dofs.count == 3) reader.fail(line.number, "more than 3 dofs");
        bone.dofs.channels[static_cast<std::size_t>(bone.dofs.count++)] = code;
    }
}

void read_bone(TextLexer& reader, BoneDef& bone, std::vector<std::string_view>& tokens) {
    const std::string closing = "expected 'end' to close the bone block opened on line " + std::to_string(bone.begin_line);
    bool last_was_limits = false;
    Line line;
    for (;;) {
        if (!reader.next_content_line(line)) reader.fail(reader.end_line(), closing + ", found end of file");
        if (line.text.front() == '(') {
            if (!last_was_limits)
                reader.fail(line.number, "a line starting with '(' must continue 'limits' (expected a bone keyword)");
            read_limit_pairs(reader, line.number, line.text, bone);
            continue;
        }
        last_was_limits = false;
        split_blanks(line.text, tokens);
        const std::string_view key = tokens[0];
        auto once = [&](int& seen) {
            if (seen)
                reader.fail(line.number, "the bone block has a second " + quote_token(key) + " (first on line " +
                                             std::to_string(seen) + ")");
            seen = line.number;
        };
        if (iequals(key, "end")) {
            if (tokens.size() != 1) reader.fail(line.number, "expected nothing after 'end', found " + quote_token(tokens[1]));
            break;
        }
        if (is_section_line(line) || iequals(key, "begin")) reader.fail(line.number, closing + ", found " + quote_token(key));
        if (iequals(key, "id")) {
            std::int64_t id = 0;
            if (bone.has_id) reader.fail(line.number, "the bone block has a second 'id'");
            if (tokens.size() != 2 || !parse_integer(tokens[1], id))
                reader.fail(line.number, "expected a whole number after 'id', found " +
                                             quote_token(trim_blanks(line.text.substr(2))));
            bone.has_id = true;
        } else if (iequals(key, "name")) {
            once(bone.name_line);
            if (tokens.size() != 2)
                reader.fail(line.number, "expected one word after 'name', found " + std::to_string(tokens.size() - 1));
            bone.name = tokens[1];
        } else if (iequals(key, "direction")) {
            once(bone.direction_line);
            bone.direction = read_three(reader, line, tokens, "bone direction");
        } else if (iequals(key, "length")) {
            once(bone.length_line);
            if (tokens.size() != 2)
                reader.fail(line.number, "'length' needs 1 number, found " + std::to_string(tokens.size() - 1));
            bone.length = read_number(reader, line.number, tokens[1], "bone length");
            if (bone.length < 0.0) reader.fail(line.number, "bone length must not be negative, found " + quote_token(tokens[1]));
        } else if (iequals(key, "axis")) {
            once(bone.axis_line);
            if (tokens.size() != 4 && tokens.size() != 5)
                reader.fail(line.number, "'axis' needs 3 angles and an order such as XYZ, found " +
                                             std::to_string(tokens.size() - 1) + " values");
            for (std::size_t i = 0; i < 3; ++i) bone.axis[i] = read_number(reader, line.number, tokens[i + 1], "axis angle");
            if (tokens.size() == 5 && !parse_axis_order(tokens[4], bone.axis_order))
                reader.fail(line.number, "expected an axis order such as XYZ, found " + quote_token(tokens[4]));
        } else if (iequals(key, "dof")) {
            once(bone.dof_line);
            read_dofs(reader, line, tokens, bone);
        } else if (iequals(key, "limits")) {
            once(bone.limits_line);
            read_limit_pairs(reader, line.number, trim_blanks(line.text.substr(6)), bone);
            last_was_limits = true;
        } else if (iequals(key, "bodymass") || iequals(key, "cofmass")) {
            for (std::size_t i = 1; i < tokens.size(); ++i) read_number(reader, line.number, tokens[i], std::string(key));
        } else {
            reader.fail(line.number, "expected id, name, direction, length, axis, dof, limits or end in the bone block "
                                     "opened on line " + std::to_string(bone.begin_line) + ", found " + quote_token(key));
        }
    }
    const std::pair<int, const char*> required[] = {
        {bone.name_line, "name"}, {bone.direction_line, "direction"}, {bone.length_line, "length"}, {bone.axis_line, "axis"}};
    for (const auto& [seen, name] : required)
        if (!seen)
            reader.fail(line.number, "the bone block opened on line " + std::to_string(bone.begin_line) + " lacks '" +
                                         name + "'");
    if (bone.limits_line && bone.limit_pairs != bone.dofs.count)
        reader.fail(bone.limits_line, "bone " + quote_token(bone.name) + " has " + std::to_string(bone.dofs.count) +
                                          " dofs but " + std::to_string(bone.limit_pairs) +
                                          " limit pairs (expected one '(lo hi)' per dof)");
}

void read_bonedata(TextLexer& reader, AsfFile& asf, std::vector<std::string_view>& tokens) {
    Line line;
    while (reader.peek_content_line(line) && !is_section_line(line)) {
        reader.next_content_line(line);
        if (!iequals(line.text, "begin"))
            reader.fail(line.number, "expected 'begin' to start a bone block in :bonedata, found " + quote_token(line.text));
        if (static_cast<int>(asf.bones.size()) >= kMaxBones)
            reader.fail(line.number, "too many bones: more than " + std::to_string(kMaxBones) + " (the limit)");
        BoneDef bone;
        bone.begin_line = line.number;
        read_bone(reader, bone, tokens);
        asf.bones.push_back(bone);
    }
}

void read_hierarchy(TextLexer& reader, AsfFile& asf, std::vector<std::string_view>& tokens) {
    Line line;
    if (!reader.next_content_line(line)) reader.fail(reader.end_line(), "expected 'begin' after :hierarchy, found end of file");
    if (!iequals(line.text, "begin"))
        reader.fail(line.number, "expected 'begin' after :hierarchy, found " + quote_token(line.text));
    const int begin_line = line.number;
    for (;;) {
        const std::string closing = "expected 'end' to close the :hierarchy block opened on line " + std::to_string(begin_line);
        if (!reader.next_content_line(line)) reader.fail(reader.end_line(), closing + ", found end of file");
        if (iequals(line.text, "end")) return;
        if (is_section_line(line) || iequals(line.text, "begin")) reader.fail(line.number, closing + ", found " + quote_token(line.text));
        split_blanks(line.text, tokens);
        asf.hierarchy.push_back(HierarchyLine{line.number, tokens});
    }
}

AsfFile read_asf_file(std::string_view text, const std::string& file) {
    TextLexer reader(text, file);
    reader.reject_control_bytes("ASF");
    reader.skip_utf8_bom();
    AsfFile asf;
    std::vector<std::string_view> tokens;
    struct Section {
        const char* name;
        int line;
    };
    std::array<Section, 7> sections = {{{":version", 0}, {":name", 0}, {":units", 0}, {":documentation", 0},
                                        {":root", 0}, {":bonedata", 0}, {":hierarchy", 0}}};
    Line line;
    while (reader.next_content_line(line)) {
        split_blanks(line.text, tokens);
        const std::string_view key = tokens[0];
        if (!is_section_line(line))
            reader.fail(line.number, "expected an ASF section keyword (':version', ':name', ':units', ':documentation', "
                                     "':root', ':bonedata' or ':hierarchy'), found " + quote_token(key));
        Section* section = nullptr;
        for (Section& s : sections)
            if (iequals(key, s.name)) section = &s;
        if (!section) {
            skip_section_body(reader);  // e.g. ':skin': nothing this runtime uses
            continue;
        }
        if (section->line)
            reader.fail(line.number, "second " + std::string(section->name) + " section (the first is on line " +
                                         std::to_string(section->line) + ")");
        section->line = line.number;
        const std::string_view name = section->name;
        if (name == ":units" || name == ":root" || name == ":bonedata" || name == ":hierarchy") {
            if (tokens.size() > 1)
                reader.fail(line.number, "expected nothing after " + std::string(name) + " on its line, found " +
                                             quote_token(tokens[1]));
        }
        if (name == ":units") {
            read_units(reader, asf, tokens);
        } else if (name == ":root") {
            asf.root.line = line.number;
            read_root(reader, asf, tokens);
        } else if (name == ":bonedata") {
            asf.bonedata_line = line.number;
            read_bonedata(reader, asf, tokens);
        } else if (name == ":hierarchy") {
            asf.hierarchy_line = line.number;
            read_hierarchy(reader, asf, tokens);
        } else if (name == ":documentation") {
            skip_section_body(reader);
        }
        // :version and :name: the rest of their line is free text.
    }
    if (!asf.root.line) reader.fail(reader.end_line(), "expected a ':root' section, found end of file");
    if (!asf.bonedata_line) reader.fail(reader.end_line(), "expected a ':bonedata' section, found end of file");
    if (!asf.hierarchy_line) reader.fail(reader.end_line(), "expected a ':hierarchy' section, found end of file");
    return asf;
}

// Node n of the bone tree: 0 is the root, 1 + b is bone b.
std::unordered_map<std::string_view, int> bones_by_name(const AsfFile& asf, const TextLexer& reader) {
    std::unordered_map<std::string_view, int> by_name;
    for (int b = 0; b < static_cast<int>(asf.bones.size()); ++b) {
        const BoneDef& bone = asf.bones[static_cast<std::size_t>(b)];
        if (bone.name == "root")
            reader.fail(bone.name_line, "a bone cannot be named 'root' (the name is the root's)");
        const auto [it, inserted] = by_name.emplace(bone.name, b);
        if (!inserted)
            reader.fail(bone.name_line, "duplicate bone name " + quote_token(bone.name) + " (first defined on line " +
                                            std::to_string(asf.bones[static_cast<std::size_t>(it->second)].name_line) + ")");
    }
    return by_name;
}

struct BoneTree {
    std::vector<int> parent;       // per node; -1 for the root and unattached bones
    std::vector<int> parent_line;  // the :hierarchy line that gave the parent; 0 for none
    std::vector<std::vector<int>> children;
};

// Parents and children from the :hierarchy lines.
BoneTree link_hierarchy(const AsfFile& asf, const TextLexer& reader) {
    const std::unordered_map<std::string_view, int> by_name = bones_by_name(asf, reader);
    const std::size_t nodes = asf.bones.size() + 1;
    BoneTree tree{std::vector<int>(nodes, -1), std::vector<int>(nodes, 0), std::vector<std::vector<int>>(nodes)};
    auto node_of = [&](std::string_view name, int line) {
        if (name == "root") return 0;
        const auto it = by_name.find(name);
        if (it == by_name.end())
            reader.fail(line, "unknown bone " + quote_token(name) + " in :hierarchy (expected 'root' or a bone from :bonedata)");
        return it->second + 1;
    };
    for (const HierarchyLine& h : asf.hierarchy) {
        const int p = node_of(h.names[0], h.line);
        for (std::size_t i = 1; i < h.names.size(); ++i) {
            const int c = node_of(h.names[i], h.line);
            if (c == 0) reader.fail(h.line, "the root cannot be a child in :hierarchy");
            if (c == p) reader.fail(h.line, "bone " + quote_token(h.names[i]) + " cannot be its own parent");
            const auto cu = static_cast<std::size_t>(c);
            if (tree.parent_line[cu])
                reader.fail(h.line, "bone " + quote_token(h.names[i]) + " already has a parent (line " +
                                        std::to_string(tree.parent_line[cu]) + ")");
            tree.parent[cu] = p;
            tree.parent_line[cu] = h.line;
            tree.children[static_cast<std::size_t>(p)].push_back(c);
        }
    }
    return tree;
}

struct JointOrder {
    std::vector<int> joint_of;  // per node; -1 for a node the walk did not reach
    std::vector<int> nodes;     // nodes in joint order
};

// A depth-first walk from the root with an explicit stack: a topological joint
// order, children in the order :hierarchy lists them.
JointOrder depth_first_order(const BoneTree& tree) {
    const std::size_t nodes = tree.children.size();
    JointOrder out{std::vector<int>(nodes, -1), {}};
    out.nodes.reserve(nodes);
    struct Visit {
        int node;
        std::size_t next_child;
    };
    std::vector<Visit> stack;
    out.joint_of[0] = 0;
    out.nodes.push_back(0);
    stack.push_back({0, 0});
    while (!stack.empty()) {
        Visit& top = stack.back();
        const auto& kids = tree.children[static_cast<std::size_t>(top.node)];
        if (top.next_child == kids.size()) {
            stack.pop_back();
            continue;
        }
        const int child = kids[top.next_child++];
        // Every node has at most one parent and the root none, so no node is
        // reached twice and the walk ends.
        out.joint_of[static_cast<std::size_t>(child)] = static_cast<int>(out.nodes.size());
        out.nodes.push_back(child);
        stack.push_back({child, 0});  // may reallocate: `top` is dead from here
    }
    return out;
}

void check_all_reachable(const AsfFile& asf, const BoneTree& tree, const JointOrder& order, const TextLexer& reader) {
    for (std::size_t b = 0; b < asf.bones.size(); ++b) {
        const std::size_t n = b + 1;
        if (order.joint_of[n] >= 0) continue;
        const BoneDef& bone = asf.bones[b];
        if (!tree.parent_line[n])
            reader.fail(bone.name_line, "bone " + quote_token(bone.name) +
                                            " is not attached: no :hierarchy line names it as a child (expected "
                                            "every bone to be reachable from root)");
        reader.fail(tree.parent_line[n], "bone " + quote_token(bone.name) + " is not reachable from root: its parents form a cycle");
    }
}

// Each node's bone as direction · length with a unit direction (see the
// decisions at the top); node 0 has no bone.
std::vector<vec3> bone_vectors(const AsfFile& asf, const TextLexer& reader) {
    std::vector<vec3> bone_vector(asf.bones.size() + 1, vec3(0.0f));
    for (std::size_t b = 0; b < asf.bones.size(); ++b) {
        const BoneDef& bone = asf.bones[b];
        const auto& d = bone.direction;
        const double norm = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (!(norm >= kMinDirectionNorm)) {
            if (bone.length != 0.0)
                reader.fail(bone.direction_line, "bone " + quote_token(bone.name) + " has a zero direction (expected a unit vector)");
            continue;
        }
        const double scale = bone.length / norm;
        bone_vector[b + 1] =
            vec3(static_cast<float>(d[0] * scale), static_cast<float>(d[1] * scale), static_cast<float>(d[2] * scale));
    }
    return bone_vector;
}

// C: the axis frame from its three angles in the file's unit.
quat axis_frame(const std::array<double, 3>& angles, const std::array<int, 3>& order, double angle_scale) {
    const std::array<double, 3> radians = {angles[0] * angle_scale, angles[1] * angle_scale, angles[2] * angle_scale};
    return euler_rotation(radians, order);
}

// The joints in `order`, each with its parent joint, rest offset and dofs.
AsfSkeleton assemble_skeleton(const AsfFile& asf, const BoneTree& tree, const JointOrder& order,
                              const std::vector<vec3>& bone_vector) {
    const double angle_scale = asf.degrees ? det::kDegToRad : 1.0;
    const std::size_t nodes = tree.children.size();
    AsfSkeleton out;
    out.length_unit = asf.length_unit;
    out.degrees = asf.degrees;
    Skeleton& sk = out.skeleton;
    sk.joint_names.reserve(nodes);
    sk.parents.reserve(nodes);
    sk.rest_offsets.reserve(nodes);
    out.dofs.reserve(nodes);
    for (int node : order.nodes) {
        const auto n = static_cast<std::size_t>(node);
        if (node == 0) {
            const RootDef& root = asf.root;
            sk.joint_names.emplace_back("root");
            sk.parents.push_back(kNoParent);
            sk.rest_offsets.emplace_back(static_cast<float>(root.position[0]), static_cast<float>(root.position[1]),
                                         static_cast<float>(root.position[2]));
            AsfSkeleton::Dofs dofs = root.dofs;
            dofs.axis = axis_frame(root.orientation, root.axis_order, angle_scale);
            out.dofs.push_back(dofs);
            continue;
        }
        const BoneDef& bone = asf.bones[n - 1];
        const auto p = static_cast<std::size_t>(tree.parent[n]);
        sk.joint_names.emplace_back(bone.name);
        sk.parents.push_back(order.joint_of[p]);
        sk.rest_offsets.push_back(bone_vector[p]);  // the parent's end; zero for the root
        AsfSkeleton::Dofs dofs = bone.dofs;
        dofs.axis = axis_frame(bone.axis, bone.axis_order, angle_scale);
        out.dofs.push_back(dofs);
        if (tree.children[n].empty()) {
            sk.end_site_parents.push_back(order.joint_of[n]);
            sk.end_site_offsets.push_back(bone_vector[n]);
        }
    }
    return out;
}

// Bone names → the skeleton: parents from :hierarchy, then a depth-first walk
// from the root for a topological joint order.
AsfSkeleton build_skeleton(const AsfFile& asf, std::string_view text, const std::string& file) {
    const TextLexer reader(text, file);  // for fail() only
    const BoneTree tree = link_hierarchy(asf, reader);
    const JointOrder order = depth_first_order(tree);
    check_all_reachable(asf, tree, order, reader);
    return assemble_skeleton(asf, tree, order, bone_vectors(asf, reader));
}

AsfSkeleton parse_asf(std::string_view text, const std::string& file) {
    return build_skeleton(read_asf_file(text, file), text, file);
}

// ---------------------------------------------------------------- AMC

std::string dof_names(const AsfSkeleton::Dofs& dofs) {
    static constexpr const char* kNames[6] = {"tx", "ty", "tz", "rx", "ry", "rz"};
    std::string out;
    for (int c = 0; c < dofs.count; ++c) {
        if (c) out += ' ';
        out += kNames[dofs.channels[static_cast<std::size_t>(c)]];
    }
    return out;
}

// One joint's local transform from its AMC values: translation channels
// replace rest-offset components; rotations apply in the order listed.
void apply_dofs(const AsfSkeleton::Dofs& dofs, const double* values, double angle_scale, quat& rotation,
                vec3& translation) {
    quat motion = quat_identity();
    for (int c = 0; c < dofs.count; ++c) {
        const int channel = dofs.channels[static_cast<std::size_t>(c)];
        if (channel < kRotateX) {
            translation[channel] = static_cast<float>(values[c]);
        } else {
            motion = quat_mul(axis_rotation(channel - kRotateX, values[c] * angle_scale), motion);
        }
    }
    rotation = quat_normalize(quat_mul(quat_mul(dofs.axis, motion), quat_conjugate(dofs.axis)));
}

void read_amc(const AsfSkeleton& asf, std::string_view text, const std::string& file, Clip& clip) {
    TextLexer reader(text, file);
    reader.reject_control_bytes("AMC");
    reader.skip_utf8_bom();
    const Skeleton& sk = asf.skeleton;
    const auto joints = static_cast<std::size_t>(sk.joint_count());
    std::unordered_map<std::string_view, int> by_name;
    std::size_t dof_joints = 0;
    for (std::size_t j = 0; j < joints; ++j) {
        by_name.emplace(sk.joint_names[j], static_cast<int>(j));
        if (asf.dofs[j].count > 0) ++dof_joints;
    }

    if (dof_joints == 0) reader.fail(1, "no bone of the ASF skeleton has dofs, so there is no motion to read");

    bool degrees = asf.degrees;
    Line line;
    while (reader.peek_content_line(line) && is_section_line(line)) {
        reader.next_content_line(line);
        if (iequals(line.text, ":DEGREES")) degrees = true;
        else if (iequals(line.text, ":RADIANS")) degrees = false;
        // :FULLY-SPECIFIED and other header flags change nothing here.
    }
    const double angle_scale = degrees ? det::kDegToRad : 1.0;

    // Each frame has a number line and one line per bone with dofs, so this
    // bounds the frame count by the text actually present.
    std::size_t line_ends = 1;
    for (char c : text)
        if (c == '\n') ++line_ends;
    const std::size_t max_frames = static_cast<std::size_t>(kMaxPoseSamples) / joints;
    clip.rotations.reserve(std::min(line_ends / (1 + dof_joints), max_frames) * joints);
    clip.translations.reserve(clip.rotations.capacity());

    std::vector<std::string_view> tokens;
    std::vector<double> values;
    std::vector<int> seen_in_frame(joints, 0);  // frame number that last listed the joint
    std::int64_t frame = 0;
    int frame_line = 0;
    auto finish_frame = [&] {
        if (frame == 0) return;
        for (std::size_t j = 0; j < joints; ++j)
            if (asf.dofs[j].count > 0 && seen_in_frame[j] != frame)
                reader.fail(frame_line, "frame " + std::to_string(frame) + " has no line for bone " +
                                            quote_token(sk.joint_names[j]) + " (expected every bone with dofs in every frame)");
    };
    while (reader.next_content_line(line)) {
        split_blanks(line.text, tokens);
        std::int64_t number = 0;
        if (tokens.size() == 1 && parse_integer(tokens[0], number)) {
            finish_frame();
            if (number != frame + 1)
                reader.fail(line.number, "expected frame number " + std::to_string(frame + 1) + ", found " +
                                             quote_token(tokens[0]) + " (frames are numbered 1, 2, 3, ...)");
            if (static_cast<std::size_t>(number) > max_frames)
                reader.fail(line.number, "too many frames: " + std::to_string(number) + " × " + std::to_string(joints) +
                                             " joints exceeds the limit of " + std::to_string(kMaxPoseSamples) +
                                             " pose samples");
            frame = number;
            frame_line = line.number;
            clip.rotations.insert(clip.rotations.end(), joints, quat_identity());
            clip.translations.insert(clip.translations.end(), sk.rest_offsets.begin(), sk.rest_offsets.end());
            continue;
        }
        if (is_section_line(line))
            reader.fail(line.number, "expected a frame number or a bone line, found " + quote_token(tokens[0]) +
                                         " (header keywords go before the first frame)");
        if (frame == 0) reader.fail(line.number, "expected frame number 1, found " + quote_token(tokens[0]));
        const auto it = by_name.find(tokens[0]);
        if (it == by_name.end())
            reader.fail(line.number, "unknown bone " + quote_token(tokens[0]) + " in frame " + std::to_string(frame) +
                                         " (expected a bone of the ASF skeleton)");
        const auto j = static_cast<std::size_t>(it->second);
        if (seen_in_frame[j] == frame)
            reader.fail(line.number, "bone " + quote_token(tokens[0]) + " is listed twice in frame " + std::to_string(frame));
        seen_in_frame[j] = static_cast<int>(frame);
        const AsfSkeleton::Dofs& dofs = asf.dofs[j];
        const std::size_t count = tokens.size() - 1;
        if (count != static_cast<std::size_t>(dofs.count))
            reader.fail(line.number, "bone " + quote_token(tokens[0]) + " has " + std::to_string(count) + " values in frame " +
                                         std::to_string(frame) + ", expected " + std::to_string(dofs.count) +
                                         (dofs.count ? " (" + dof_names(dofs) + ")" : std::string(" (it has no dof)")));
        values.resize(count);
        for (std::size_t i = 0; i < count; ++i)
            values[i] = read_number(reader, line.number, tokens[i + 1],
                                    "value " + std::to_string(i + 1) + " of bone " + quote_token(tokens[0]));
        const std::size_t at = static_cast<std::size_t>(frame - 1) * joints + j;
        apply_dofs(dofs, values.data(), angle_scale, clip.rotations[at], clip.translations[at]);
    }
    if (frame == 0) reader.fail(reader.end_line(), "expected frame number 1, found end of file");
    finish_frame();
    clip.frame_count = static_cast<int>(frame);
}

std::string read_file(const std::string& path, const char* kind) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw ImportError(path, 0, "cannot open the file for reading");
    return read_capped_text(in, path, std::string("an ") + kind + " file");
}

}  // namespace

Clip import_asf_amc(std::string_view asf_text, const std::string& asf_name, std::string_view amc_text,
                    const std::string& amc_name, const AmcOptions& options) {
    if (!(options.frame_rate > 0.0) || !std::isfinite(options.frame_rate))
        throw ImportError(amc_name, 0, "the frame rate must be a positive number, found " +
                                           std::to_string(options.frame_rate));
    const AsfSkeleton asf = parse_asf(asf_text, asf_name);
    Clip clip;
    clip.name = clip_name_from_path(amc_name);
    clip.skeleton = asf.skeleton;
    clip.frame_rate = options.frame_rate;
    clip.length_unit = asf.length_unit;
    clip.animated_translation.assign(asf.dofs.size(), false);
    for (int c = 0; c < asf.dofs[0].count; ++c)
        if (asf.dofs[0].channels[static_cast<std::size_t>(c)] < kRotateX) clip.animated_translation[0] = true;
    read_amc(asf, amc_text, amc_name, clip);
    // Holds by construction; a parser bug should surface as an error, not as a
    // clip that breaks its users.
    if (const Outcome valid = validate_clip(clip); !valid.ok())
        throw ImportError(amc_name, 0, "inconsistent clip: " + valid.problem());
    return clip;
}

Clip load_asf_amc_files(const std::string& asf_path, const std::string& amc_path, const AmcOptions& options) {
    const std::string asf_text = read_file(asf_path, "ASF");
    const std::string amc_text = read_file(amc_path, "AMC");
    return import_asf_amc(asf_text, asf_path, amc_text, amc_path, options);
}

Skeleton import_asf_skeleton(std::string_view asf_text, const std::string& asf_name) {
    AsfSkeleton asf = parse_asf(asf_text, asf_name);
    if (const Outcome valid = validate_skeleton(asf.skeleton); !valid.ok())
        throw ImportError(asf_name, 0, "inconsistent skeleton: " + valid.problem());
    return std::move(asf.skeleton);
}

}  // namespace marionette
