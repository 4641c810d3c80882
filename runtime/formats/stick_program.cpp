#include "runtime/formats/stick_program.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "runtime/math/det_math.hpp"

namespace marionette {

namespace {
constexpr double kMaxSegmentSeconds = 3600.0;
constexpr double kMaxProgramSeconds = 24 * 3600.0;
constexpr const char* kFieldNames[6] = {"lx", "ly", "rx", "ry", "lt", "rt"};

double& field(StickValues& v, int i) {
    switch (i) {
        case 0: return v.lx;
        case 1: return v.ly;
        case 2: return v.rx;
        case 3: return v.ry;
        case 4: return v.lt;
        default: return v.rt;
    }
}
double field(const StickValues& v, int i) { return field(const_cast<StickValues&>(v), i); }

std::vector<std::string_view> split_words(std::string_view line) {
    std::vector<std::string_view> words;
    size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
        size_t j = i;
        while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
        if (j > i) words.push_back(line.substr(i, j - i));
        i = j;
    }
    return words;
}

bool parse_number(std::string_view s, double& out) {
    if (!s.empty() && s[0] == '+') s.remove_prefix(1);
    if (s.empty()) return false;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && ptr == s.data() + s.size() && std::isfinite(out);
}

struct LineParser {
    const std::string& file;
    int line;
    [[noreturn]] void fail(const std::string& message) const { throw ImportError(file, line, message); }

    double duration(std::string_view word) const {
        double scale = 1.0;
        std::string_view number = word;
        if (word.size() > 2 && word.substr(word.size() - 2) == "ms") {
            scale = 0.001;
            number = word.substr(0, word.size() - 2);
        } else if (word.size() > 1 && word.back() == 's') {
            number = word.substr(0, word.size() - 1);
        } else {
            fail("expected a duration such as 1.5s or 250ms, got '" + std::string(word) + "'");
        }
        double value = 0.0;
        if (!parse_number(number, value) || value < 0.0)
            fail("expected a non-negative duration such as 1.5s or 250ms, got '" + std::string(word) + "'");
        value *= scale;
        if (value > kMaxSegmentSeconds) fail("duration " + std::string(word) + " is longer than one hour");
        return value;
    }

    // key=value with value parsed as a number; returns the key.
    std::string_view key_value(std::string_view word, double& value) const {
        const size_t eq = word.find('=');
        if (eq == std::string_view::npos || eq == 0)
            fail("expected key=value, got '" + std::string(word) + "'");
        const std::string_view key = word.substr(0, eq);
        const std::string_view text = word.substr(eq + 1);
        if (key == "stick") return key;  // handled by the caller (not a number)
        if (!parse_number(text, value))
            fail("expected a number after '" + std::string(key) + "=', got '" + std::string(text) + "'");
        return key;
    }
};

void parse_values(const LineParser& p, const std::vector<std::string_view>& words, size_t first, StickSegment& seg) {
    for (size_t w = first; w < words.size(); ++w) {
        double value = 0.0;
        const std::string_view key = p.key_value(words[w], value);
        int index = -1;
        for (int i = 0; i < 6; ++i)
            if (key == kFieldNames[i]) index = i;
        if (index < 0) p.fail("unknown value '" + std::string(key) + "' (expected lx, ly, rx, ry, lt or rt)");
        const double lo = index >= 4 ? 0.0 : -1.0;
        if (value < lo || value > 1.0)
            p.fail(std::string(key) + "=" + std::to_string(value) + " is out of range [" + (index >= 4 ? "0" : "-1") + ", 1]");
        seg.set_mask = static_cast<std::uint8_t>(seg.set_mask | (1u << index));
        field(seg.target, index) = value;
    }
}
}  // namespace

double StickProgram::duration_s() const {
    double total = 0.0;
    for (const StickSegment& s : segments) total += s.duration_s;
    return total;
}

StickProgram parse_stick_program(std::string_view text, const std::string& file) {
    StickProgram program;
    int line_number = 0;
    double total = 0.0;
    size_t start = 0;
    while (start < text.size()) {
        size_t end = text.find('\n', start);
        if (end == std::string_view::npos) end = text.size();
        std::string_view line = text.substr(start, end - start);
        ++line_number;
        start = end + 1;
        if (const size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
        for (char ch : line)
            if (static_cast<unsigned char>(ch) < 0x20 && ch != '\t' && ch != '\r')
                throw ImportError(file, line_number, "unexpected control character: not a stick program");
        const std::vector<std::string_view> words = split_words(line);
        if (words.empty()) continue;
        LineParser p{file, line_number};
        StickSegment seg;
        seg.line = line_number;
        const std::string_view verb = words[0];
        if (verb == "hold" || verb == "ramp") {
            seg.kind = verb == "hold" ? StickSegment::Kind::hold : StickSegment::Kind::ramp;
            if (words.size() < 2) p.fail("expected a duration after '" + std::string(verb) + "'");
            seg.duration_s = p.duration(words[1]);
            parse_values(p, words, 2, seg);
        } else if (verb == "circle") {
            seg.kind = StickSegment::Kind::circle;
            if (words.size() < 2) p.fail("expected a duration after 'circle'");
            seg.duration_s = p.duration(words[1]);
            for (size_t w = 2; w < words.size(); ++w) {
                double value = 0.0;
                const std::string_view key = p.key_value(words[w], value);
                if (key == "stick") {
                    const std::string_view which = words[w].substr(6);
                    if (which != "left" && which != "right") p.fail("expected stick=left or stick=right");
                    seg.right_stick = which == "right";
                } else if (key == "radius") {
                    if (value < 0.0 || value > 1.0) p.fail("radius must be in [0, 1]");
                    seg.radius = value;
                } else if (key == "turns") {
                    if (value < -100.0 || value > 100.0) p.fail("turns must be in [-100, 100]");
                    seg.turns = value;
                } else if (key == "from") {
                    seg.from_deg = value;
                } else {
                    p.fail("unknown circle parameter '" + std::string(key) + "' (expected stick, radius, turns, from)");
                }
            }
        } else if (verb == "press") {
            seg.kind = StickSegment::Kind::press;
            if (words.size() < 2 || words.size() > 3) p.fail("expected 'press BUTTON [DURATION]'");
            // BUTTON or a chord BUTTON+BUTTON+... (held together, e.g. back+start).
            std::string_view names = words[1];
            while (true) {
                const std::size_t plus = names.find('+');
                const std::string_view name = names.substr(0, plus);
                const auto button = button_from_name(name);
                if (!button) p.fail("unknown button '" + std::string(name) + "'");
                seg.buttons |= button_bit(*button);
                if (plus == std::string_view::npos) break;
                names.remove_prefix(plus + 1);
            }
            seg.duration_s = words.size() == 3 ? p.duration(words[2]) : 0.1;
        } else {
            p.fail("unknown command '" + std::string(verb) + "' (expected hold, ramp, circle or press)");
        }
        total += seg.duration_s;
        if (total > kMaxProgramSeconds) p.fail("program is longer than 24 hours");
        program.segments.push_back(seg);
    }
    if (program.segments.empty()) throw ImportError(file, line_number, "program has no commands");
    return program;
}

StickProgram load_stick_program_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw ImportError(path, 0, "cannot open file");
    std::ostringstream ss;
    ss << in.rdbuf();
    StickProgram program = parse_stick_program(ss.str(), path);
    const size_t slash = path.find_last_of('/');
    program.name = path.substr(slash == std::string::npos ? 0 : slash + 1);
    return program;
}

std::vector<TickInput> render_stick_program(const StickProgram& program, int rate) {
    std::vector<TickInput> ticks;
    StickValues current;  // values at the end of the previous segment
    double segment_start = 0.0;
    std::int64_t next_tick = 0;
    for (const StickSegment& seg : program.segments) {
        const double segment_end = segment_start + seg.duration_s;
        // Ticks whose start time lies in [segment_start, segment_end).
        const auto end_tick = static_cast<std::int64_t>(std::ceil(segment_end * rate - 1e-9));
        StickValues from = current;
        StickValues to = current;
        for (int i = 0; i < 6; ++i)
            if (seg.set_mask & (1u << i)) field(to, i) = field(seg.target, i);
        bool pressed_once = false;
        for (; next_tick < end_tick; ++next_tick) {
            const double t = static_cast<double>(next_tick) / rate;
            const double u = seg.duration_s > 0.0 ? (t - segment_start) / seg.duration_s : 1.0;
            StickValues v = to;
            std::uint32_t buttons = 0;
            switch (seg.kind) {
                case StickSegment::Kind::hold:
                    break;
                case StickSegment::Kind::ramp:
                    for (int i = 0; i < 6; ++i) field(v, i) = field(from, i) + (field(to, i) - field(from, i)) * u;
                    break;
                case StickSegment::Kind::circle: {
                    const double angle = (seg.from_deg + 360.0 * seg.turns * u) * det::kDegToRad;
                    double s = 0.0, c = 0.0;
                    det::sin_cos(angle, s, c);
                    (seg.right_stick ? v.rx : v.lx) = seg.radius * c;
                    (seg.right_stick ? v.ry : v.ly) = seg.radius * s;
                    break;
                }
                case StickSegment::Kind::press:
                    buttons = seg.buttons;
                    pressed_once = true;
                    break;
            }
            TickInput in;
            in.left_x = quantize_stick(v.lx);
            in.left_y = quantize_stick(v.ly);
            in.right_x = quantize_stick(v.rx);
            in.right_y = quantize_stick(v.ry);
            in.left_trigger = quantize_trigger(v.lt);
            in.right_trigger = quantize_trigger(v.rt);
            in.buttons = buttons;
            ticks.push_back(in);
        }
        // A press shorter than a tick still lands in the tick it falls in.
        if (seg.kind == StickSegment::Kind::press && !pressed_once && !ticks.empty())
            ticks.back().buttons |= seg.buttons;
        if (seg.kind == StickSegment::Kind::circle) {
            const double angle = (seg.from_deg + 360.0 * seg.turns) * det::kDegToRad;
            double s = 0.0, c = 0.0;
            det::sin_cos(angle, s, c);
            (seg.right_stick ? to.rx : to.lx) = seg.radius * c;
            (seg.right_stick ? to.ry : to.ly) = seg.radius * s;
        }
        current = to;
        segment_start = segment_end;
    }
    return ticks;
}

}  // namespace marionette
