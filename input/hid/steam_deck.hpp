#pragma once
// Steam Deck built-in controls, 28de:1205, hidraw interface 2: 64-byte reports
// with no report id (reference: SDL2's SDL_hidapi_steamdeck.c and
// steam/controller_structs.h). The controls start in "lizard mode" (trackpad
// as mouse, buttons as keys); a feature report turns that off, and it must be
// repeated (the watchdog) or the firmware turns it back on.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "input/hid/hid_report.hpp"

namespace marionette::input::steamdeck {

inline constexpr std::size_t kReportSize = 64;
inline constexpr std::size_t kVersion = 0;        // u16 LE, 0x0001
inline constexpr std::size_t kType = 2;           // 0x09 = deck state
inline constexpr std::size_t kLength = 3;         // 64
inline constexpr std::uint16_t kReportVersion = 0x0001;
inline constexpr std::uint8_t kTypeDeckState = 0x09;
inline constexpr std::size_t kPacketNumber = 4;   // u32 LE
inline constexpr std::size_t kButtonsLow = 8;     // u32 LE
inline constexpr std::size_t kButtonsHigh = 12;   // u32 LE
inline constexpr std::size_t kLeftTrigger = 44, kRightTrigger = 46;     // u16, 0..32767
inline constexpr std::size_t kLeftStickX = 48, kLeftStickY = 50;        // s16, y up
inline constexpr std::size_t kRightStickX = 52, kRightStickY = 54;

inline constexpr std::uint32_t kR2 = 0x00000001, kL2 = 0x00000002, kR1 = 0x00000004, kL1 = 0x00000008;
inline constexpr std::uint32_t kY = 0x00000010, kB = 0x00000020, kX = 0x00000040, kA = 0x00000080;
inline constexpr std::uint32_t kDpadUp = 0x00000100, kDpadRight = 0x00000200, kDpadLeft = 0x00000400,
                               kDpadDown = 0x00000800;
inline constexpr std::uint32_t kView = 0x00001000, kSteam = 0x00002000, kMenu = 0x00004000;
inline constexpr std::uint32_t kL3 = 0x00400000, kR3 = 0x04000000;

// Feature reports (65 bytes: hidapi's report-id byte 0, then the message).
inline constexpr std::size_t kFeatureReportSize = 65;
inline constexpr std::uint8_t kClearDigitalMappings = 0x81;
inline constexpr std::uint8_t kSetSettingsValues = 0x87;
inline constexpr std::uint8_t kSettingLeftTrackpadMode = 7, kSettingRightTrackpadMode = 8;
inline constexpr std::uint8_t kSettingSmoothAbsoluteMouse = 24;
inline constexpr std::uint8_t kSettingLeftClickPressure = 52, kSettingRightClickPressure = 53;
inline constexpr std::uint16_t kTrackpadNone = 7;
inline constexpr int kWatchdogReports = 200;  // resend after this many reports, as SDL does

std::array<std::uint8_t, kFeatureReportSize> clear_digital_mappings_report();
std::array<std::uint8_t, kFeatureReportSize> disable_lizard_settings_report();

ParseStatus parse(std::span<const std::uint8_t> report, InputSample& out);

}  // namespace marionette::input::steamdeck
