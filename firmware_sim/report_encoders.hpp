#pragma once
// Byte-exact report generators: the inverse of input/hid's parsers, written from
// the same named offsets so a generated report is what the real firmware sends.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "input/hid/hid_report.hpp"
#include "input/hid/switch_pro.hpp"

namespace marionette::firmware_sim {

// What the simulated pad is doing at one instant (normalised like InputSample).
struct PadState {
    double lx = 0, ly = 0, rx = 0, ry = 0;  // [-1, 1], x right, y up
    double lt = 0, rt = 0;                  // [0, 1]
    std::uint32_t buttons = 0;              // runtime Button bits
};

struct Report {
    std::array<std::uint8_t, 80> bytes{};
    std::size_t size = 0;
    std::span<const std::uint8_t> view() const { return {bytes.data(), size}; }
    std::span<std::uint8_t> data() { return {bytes.data(), size}; }
};

// Per-report values the firmware counts itself.
struct ReportClock {
    std::uint32_t counter = 0;       // reports sent so far
    std::uint64_t device_time_us = 0;  // the pad's own clock
};

// Raw conversions shared with the evemu writer.
std::uint8_t encode_centred8(double v);   // [-1, 1] → 0..255, centre 128
std::int16_t encode_s16(double v);        // [-1, 1] → -32768..32767
std::int32_t encode_centred(double v, std::int32_t min, std::int32_t max);  // inverse of normalise_centred
std::int32_t encode_trigger(double v, std::int32_t min, std::int32_t max);  // inverse of normalise_trigger

Report encode_ds4(const PadState& s, const ReportClock& clock, bool bluetooth);
Report encode_dualsense(const PadState& s, const ReportClock& clock, bool bluetooth);
// The pad's own factory calibration decides the raw counts.
Report encode_switchpro(const PadState& s, const ReportClock& clock, const input::switchpro::Calibration& cal);
Report encode_steamdeck(const PadState& s, const ReportClock& clock);
Report encode_report(input::HidFormat format, const PadState& s, const ReportClock& clock, bool bluetooth,
                     const input::switchpro::Calibration& cal);

// The factory calibration firmware_sim's Switch Pro reports (deliberately off
// the defaults, so a test can tell whether the parser read it).
inline constexpr input::switchpro::Calibration kSimSwitchCalibration = {
    {1990, 2110, 1480, 1560, 1520, 1440}, {2070, 1950, 1500, 1530, 1470, 1550}, true};

}  // namespace marionette::firmware_sim
