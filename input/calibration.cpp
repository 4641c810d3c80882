#include "input/calibration.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>

#include "runtime/errors/import_error.hpp"

namespace marionette::input {

namespace {

using FloatField = float FamilyCalibration::*;

struct FloatKey {
    const char* key;
    FloatField field;
    double min, max;
    const char* doc;
};
const FloatKey kFloatKeys[] = {
    {"stick_range", &FamilyCalibration::stick_range, 0.1, 2.0, "deflection after centring that reads as full (1 = the device's own end stops)"},
    {"stick_deadzone", &FamilyCalibration::stick_deadzone, 0.0, 0.9, "radial deadzone, fraction of full deflection"},
    {"stick_anti_deadzone", &FamilyCalibration::stick_anti_deadzone, 0.0, 0.9, "output magnitude just outside the deadzone (cancels a game-side deadzone)"},
    {"stick_curve", &FamilyCalibration::stick_curve, 0.2, 5.0, "response exponent on the magnitude: 1 linear, 2 quadratic"},
    {"trigger_deadzone", &FamilyCalibration::trigger_deadzone, 0.0, 0.9, "trigger travel ignored at rest"},
    {"trigger_range", &FamilyCalibration::trigger_range, 0.1, 1.0, "trigger travel that reads as fully pressed"},
};

using StickField = float StickCalibration::*;
using StickBool = bool StickCalibration::*;
struct StickKey {
    const char* key;
    StickCalibration FamilyCalibration::*stick;
    StickField centre;   // null for the inversion keys
    StickBool invert;
    const char* doc;
};
const StickKey kStickKeys[] = {
    {"left_centre_x", &FamilyCalibration::left, &StickCalibration::centre_x, nullptr, "left stick x at rest (normalised), subtracted"},
    {"left_centre_y", &FamilyCalibration::left, &StickCalibration::centre_y, nullptr, "left stick y at rest"},
    {"right_centre_x", &FamilyCalibration::right, &StickCalibration::centre_x, nullptr, "right stick x at rest"},
    {"right_centre_y", &FamilyCalibration::right, &StickCalibration::centre_y, nullptr, "right stick y at rest"},
    {"invert_left_x", &FamilyCalibration::left, nullptr, &StickCalibration::invert_x, "flip the left stick's x axis"},
    {"invert_left_y", &FamilyCalibration::left, nullptr, &StickCalibration::invert_y, "flip the left stick's y axis"},
    {"invert_right_x", &FamilyCalibration::right, nullptr, &StickCalibration::invert_x, "flip the right stick's x axis"},
    {"invert_right_y", &FamilyCalibration::right, nullptr, &StickCalibration::invert_y, "flip the right stick's y axis"},
};

int line_of(const toml::node& node) { return static_cast<int>(node.source().begin.line); }

std::string known_keys() {
    std::string out;
    for (const auto& k : kStickKeys) out += (out.empty() ? "" : ", ") + std::string(k.key);
    for (const auto& k : kFloatKeys) out += ", " + std::string(k.key);
    return out;
}

std::string number_text(double v) {
    std::string s = std::to_string(v);
    while (s.size() > 1 && s.back() == '0' && s[s.size() - 2] != '.') s.pop_back();
    return s;
}

double read_number(const toml::node& node, const std::string& file, const std::string& key, double min, double max) {
    double value = 0.0;
    if (const auto* f = node.as_floating_point()) value = f->get();
    else if (const auto* i = node.as_integer()) value = static_cast<double>(i->get());
    else throw ImportError(file, line_of(node), key + ": expected a number in [" + number_text(min) + ", " + number_text(max) + "]");
    if (!std::isfinite(value) || value < min || value > max)
        throw ImportError(file, line_of(node), key + ": " + number_text(value) + " is out of range: expected a number in [" +
                                                   number_text(min) + ", " + number_text(max) + "]");
    return value;
}

// One family table's keys onto one calibration.
void apply_family_table(const toml::table& table, const std::string& table_name, const std::string& file,
                        FamilyCalibration& cal, bool allow_sdl_keys) {
    for (const auto& [key_node, node] : table) {
        const std::string key(key_node.str());
        const std::string full = table_name + "." + key;
        if (allow_sdl_keys && key == "mapping_file") continue;  // handled by the caller
        bool found = false;
        for (const auto& k : kFloatKeys)
            if (key == k.key) {
                cal.*k.field = static_cast<float>(read_number(node, file, full, k.min, k.max));
                found = true;
            }
        for (const auto& k : kStickKeys)
            if (key == k.key) {
                found = true;
                if (k.centre) {
                    (cal.*k.stick).*k.centre = static_cast<float>(read_number(node, file, full, -0.5, 0.5));
                } else {
                    const auto* b = node.as_boolean();
                    if (!b) throw ImportError(file, line_of(node), full + ": expected true or false");
                    (cal.*k.stick).*k.invert = b->get();
                }
            }
        if (!found)
            throw ImportError(file, line_of(node), full + ": unknown key (expected one of: " + known_keys() +
                                                       (allow_sdl_keys ? ", mapping_file" : "") + ")");
    }
}

}  // namespace

std::vector<InputConfigKey> input_config_schema() {
    std::vector<InputConfigKey> out;
    for (const auto& k : kStickKeys)
        out.push_back({k.key, k.centre ? "float" : "bool", k.centre ? -0.5 : 0.0, k.centre ? 0.5 : 1.0, k.doc});
    for (const auto& k : kFloatKeys) out.push_back({k.key, "float", k.min, k.max, k.doc});
    out.push_back({"mapping_file", "string", 0, 0, "[sdl] only: a gamecontrollerdb.txt-format mapping file for the SDL2 backend"});
    return out;
}

InputConfig apply_input_config_text(const InputConfig& base, std::string_view text, const std::string& file) {
    toml::table doc;
    try {
        doc = toml::parse(text, file);
    } catch (const toml::parse_error& e) {
        throw ImportError(file, static_cast<int>(e.source().begin.line), "TOML syntax error: " + std::string(e.description()));
    }
    InputConfig config = base;
    std::string tables = "default";
    for (const auto name : kDeviceFamilyNames) tables += ", " + std::string(name);
    for (const auto& [key, node] : doc) {
        const std::string name(key.str());
        const bool known = name == "default" ||
                           std::find(kDeviceFamilyNames.begin(), kDeviceFamilyNames.end(), name) != kDeviceFamilyNames.end();
        if (!known) throw ImportError(file, line_of(node), name + ": unknown table (expected one of: " + tables + ")");
        if (!node.as_table()) throw ImportError(file, line_of(node), name + ": expected a table ([" + name + "])");
    }
    // [default] first, whatever the order in the file, then each family.
    if (const toml::table* t = doc["default"].as_table())
        for (auto& cal : config.families) apply_family_table(*t, "default", file, cal, false);
    for (int f = 0; f < kDeviceFamilyCount; ++f) {
        const std::string name(kDeviceFamilyNames[static_cast<std::size_t>(f)]);
        if (const toml::table* t = doc[name].as_table())
            apply_family_table(*t, name, file, config.families[static_cast<std::size_t>(f)], name == "sdl");
    }
    if (const toml::node* m = doc["sdl"]["mapping_file"].node()) {
        const auto* s = m->as_string();
        if (!s) throw ImportError(file, line_of(*m), "sdl.mapping_file: expected a string (a file path, or \"\")");
        config.sdl_mapping_file = s->get();
        config.sdl_mapping_origin = file;
    }
    return config;
}

void calibrate_stick(const FamilyCalibration& cal, const StickCalibration& stick, bool raw, float& x_io, float& y_io) {
    double x = static_cast<double>(x_io) - stick.centre_x;
    double y = static_cast<double>(y_io) - stick.centre_y;
    if (stick.invert_x) x = -x;
    if (stick.invert_y) y = -y;
    x /= cal.stick_range;
    y /= cal.stick_range;
    if (!raw) {
        double m = std::sqrt(x * x + y * y);
        if (m > 1.0) {  // radial clamp: a square gate never reads beyond the unit circle
            x /= m;
            y /= m;
            m = 1.0;
        }
        const double dz = cal.stick_deadzone;
        if (m <= dz || m == 0.0) {
            x = y = 0.0;
        } else {
            double out = (m - dz) / (1.0 - dz);
            if (cal.stick_curve != 1.0f) out = std::pow(out, static_cast<double>(cal.stick_curve));
            out = cal.stick_anti_deadzone + (1.0 - cal.stick_anti_deadzone) * out;
            x = x / m * out;
            y = y / m * out;
        }
    }
    x_io = static_cast<float>(std::clamp(x, -1.0, 1.0));
    y_io = static_cast<float>(std::clamp(y, -1.0, 1.0));
}

float calibrate_trigger(const FamilyCalibration& cal, bool raw, float value) {
    double t = std::clamp(static_cast<double>(value) / cal.trigger_range, 0.0, 1.0);
    if (!raw) {
        const double dz = cal.trigger_deadzone;
        t = t <= dz ? 0.0 : (t - dz) / (1.0 - dz);
    }
    return static_cast<float>(t);
}

void apply_calibration(const FamilyCalibration& cal, bool raw, InputSample& s) {
    calibrate_stick(cal, cal.left, raw, s.lx, s.ly);
    calibrate_stick(cal, cal.right, raw, s.rx, s.ry);
    s.lt = calibrate_trigger(cal, raw, s.lt);
    s.rt = calibrate_trigger(cal, raw, s.rt);
}

}  // namespace marionette::input
