#pragma once
// Controller calibration, applied in one place (apply_calibration) to every
// sample of every backend before it is quantised: centre offset, range, axis
// inversion, radial deadzone, anti-deadzone and response curve for sticks;
// deadzone and range for triggers. Configured per device family from
// config/input.toml (a default compiled in, plus an optional user file). It is
// kept out of the simulation config on purpose: it acts before quantisation,
// so input logs and replays never need it.
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "input/hid/hid_report.hpp"
#include "input/input_sample.hpp"

namespace marionette::input {

enum class DeviceFamily : std::uint8_t { ds4, dualsense, switchpro, steamdeck, evdev, sdl };
inline constexpr int kDeviceFamilyCount = 6;
inline constexpr std::array<std::string_view, kDeviceFamilyCount> kDeviceFamilyNames = {
    "ds4", "dualsense", "switchpro", "steamdeck", "evdev", "sdl"};

// The calibration family of a HID report format (one family per format).
constexpr DeviceFamily family_of(HidFormat format) {
    switch (format) {
        case HidFormat::ds4: return DeviceFamily::ds4;
        case HidFormat::dualsense: return DeviceFamily::dualsense;
        case HidFormat::switchpro: return DeviceFamily::switchpro;
        case HidFormat::steamdeck: return DeviceFamily::steamdeck;
    }
    return DeviceFamily::evdev;
}

struct StickCalibration {
    float centre_x = 0.0f;  // normalised value the stick rests at; subtracted first
    float centre_y = 0.0f;
    bool invert_x = false;
    bool invert_y = false;
};

struct FamilyCalibration {
    StickCalibration left;
    StickCalibration right;
    float stick_range = 1.0f;          // deflection (after centring) that counts as full
    float stick_deadzone = 0.0f;       // radial; below this magnitude the stick reads 0
    float stick_anti_deadzone = 0.0f;  // output magnitude just outside the deadzone
    float stick_curve = 1.0f;          // response exponent: 1 linear, 2 quadratic
    float trigger_deadzone = 0.0f;
    float trigger_range = 1.0f;        // trigger travel that counts as fully pressed
};

struct InputConfig {
    std::array<FamilyCalibration, kDeviceFamilyCount> families{};
    std::string sdl_mapping_file;      // gamecontrollerdb.txt-format file; empty: SDL's built-ins
    std::string sdl_mapping_origin;    // the config file the path came from (for messages)
    const FamilyCalibration& family(DeviceFamily f) const { return families[static_cast<std::size_t>(f)]; }
};

struct InputConfigKey {
    std::string key;   // within a family table ([default], [ds4], ...) or [sdl]
    std::string type;  // "float", "bool" or "string"
    double min = 0, max = 0;
    std::string doc;
};
std::vector<InputConfigKey> input_config_schema();

// Applies TOML text on top of `base`: [default] sets every family, then each
// family table ([ds4] [dualsense] [switchpro] [steamdeck] [evdev] [sdl]) sets its
// own. Throws ImportError naming the file, line and key.
InputConfig apply_input_config_text(const InputConfig& base, std::string_view toml_text, const std::string& file_name);

// Stick and trigger maths on one sample. raw = true keeps centre, range and
// inversion (each axis clamped to [-1, 1]) but skips the radial clamp,
// deadzone, anti-deadzone and the response curve
// (`input monitor --raw`, `input decode`).
void apply_calibration(const FamilyCalibration& cal, bool raw, InputSample& sample);

// The stick part alone, for tests and benchmarks.
void calibrate_stick(const FamilyCalibration& cal, const StickCalibration& stick, bool raw, float& x, float& y);
float calibrate_trigger(const FamilyCalibration& cal, bool raw, float value);

}  // namespace marionette::input
