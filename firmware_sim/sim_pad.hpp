#pragma once
// The simulated controller: a stick program played at a report rate through the
// seeded faults, as HID reports of one of the four formats or as the frames of
// an evdev gamepad (written as an evemu-record event stream for umockdev).
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "firmware_sim/faults.hpp"
#include "firmware_sim/report_encoders.hpp"
#include "runtime/formats/stick_program.hpp"

namespace marionette::firmware_sim {

inline constexpr int kMinRateHz = 125;
inline constexpr int kMaxRateHz = 8000;

struct SimPadOptions {
    std::optional<input::HidFormat> hid_format;  // empty: an evdev pad (evemu stream)
    int rate_hz = 1000;
    FaultSpec faults;
    bool bluetooth = false;                      // ds4 / dualsense Bluetooth reports
    input::switchpro::Calibration switch_calibration = kSimSwitchCalibration;
};

struct SimFrame {
    enum class Kind : std::uint8_t { report, unplug, replug, syn_dropped };
    Kind kind = Kind::report;
    std::int64_t t_ns = 0;      // when the device sends it, from the stream's start
    PadState state;             // what the pad reports (after noise, drift, quantisation)
    Report report;              // HID streams only
    bool corrupted = false;
    bool duplicate = false;
};

struct SimStats {
    std::uint64_t reports = 0;       // frames of kind report, duplicates included
    std::uint64_t dropped = 0;
    std::uint64_t duplicated = 0;
    std::uint64_t corrupted = 0;
    std::uint64_t unplugs = 0;
    std::uint64_t syn_dropped = 0;
};

struct SimStream {
    std::vector<SimFrame> frames;
    SimStats stats;
    int rate_hz = 0;
};

// Throws std::invalid_argument for a rate outside [125, 8000] Hz.
SimStream simulate_pad(const StickProgram& program, const SimPadOptions& options);

// HID streams: the reports concatenated, each exactly as hidraw's read() returns it.
std::vector<std::uint8_t> concatenate_reports(const SimStream& stream);

// ---- evdev pads --------------------------------------------------------------

enum class EvdevPadModel : std::uint8_t { xbox, dualsense };
std::optional<EvdevPadModel> evdev_pad_model_from_name(const std::string& name);

struct EvdevAxis {
    std::uint16_t code;
    std::int32_t min, max, fuzz, flat;
};
struct EvdevPadDescription {
    std::string name;
    std::uint16_t bustype, vendor, product, version;
    EvdevAxis left_x, left_y, right_x, right_y, left_trigger, right_trigger, hat_x, hat_y;
    std::array<std::uint16_t, 11> keys;  // south east west north tl tr select start mode thumbl thumbr
    std::uint16_t key_tl2 = 0, key_tr2 = 0;  // digital trigger bits, when the pad has them
};
// Xbox 360-style (the kernel's xpad) and DualSense (hid-playstation) as the
// kernel exposes them; tests/data/umockdev holds the matching descriptions.
const EvdevPadDescription& evdev_pad_description(EvdevPadModel model);

// An evemu-record stream (header, then one E: line per event): each report is a
// frame of the axes and keys that changed, ended by SYN_REPORT (the kernel sends
// no empty frames); a syn_dropped frame becomes SYN_DROPPED plus the SYN_REPORT
// ending the lost packet, and the next frame that changes anything carries the
// full state.
std::string write_evemu_stream(const SimStream& stream, const EvdevPadDescription& pad);

}  // namespace marionette::firmware_sim
