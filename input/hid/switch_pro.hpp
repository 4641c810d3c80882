#pragma once
// Nintendo Switch Pro Controller, full input report 0x30 (references: the
// kernel's hid-nintendo, SDL2's SDL_hidapi_switch.c, dekuNukem's
// Nintendo_Switch_Reverse_Engineering notes). 12-bit sticks, normalised with the
// factory stick calibration read from SPI flash, or documented defaults when it
// cannot be read.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "input/hid/hid_report.hpp"

namespace marionette::input::switchpro {

inline constexpr std::uint8_t kFullReportId = 0x30;
inline constexpr std::uint8_t kSubcommandReplyId = 0x21;
inline constexpr std::uint8_t kUsbReplyId = 0x81;
inline constexpr std::size_t kUsbReportSize = 64;  // hidraw over USB
inline constexpr std::size_t kBtReportSize = 49;   // hidraw over Bluetooth

inline constexpr std::size_t kTimer = 1;           // increments per report
inline constexpr std::size_t kButtonsRight = 3;    // Y 0, X 1, B 2, A 3, SR 4, SL 5, R 6, ZR 7
inline constexpr std::size_t kButtonsShared = 4;   // minus 0, plus 1, R stick 2, L stick 3, home 4, capture 5
inline constexpr std::size_t kButtonsLeft = 5;     // down 0, up 1, right 2, left 3, SR 4, SL 5, L 6, ZL 7
inline constexpr std::size_t kLeftStick = 6;       // 3 bytes: x = 12 low bits, y = 12 high bits; y up
inline constexpr std::size_t kRightStick = 9;

inline constexpr std::uint8_t kY = 0x01, kX = 0x02, kB = 0x04, kA = 0x08, kR = 0x40, kZR = 0x80;
inline constexpr std::uint8_t kMinus = 0x01, kPlus = 0x02, kRStick = 0x04, kLStick = 0x08, kHome = 0x10, kCapture = 0x20;
inline constexpr std::uint8_t kDown = 0x01, kUp = 0x02, kRight = 0x04, kLeft = 0x08, kL = 0x40, kZL = 0x80;

// Subcommands (output report 0x01) and the SPI flash block holding the factory
// stick calibration: 9 bytes left stick, then 9 bytes right stick.
inline constexpr std::uint8_t kOutputSubcommand = 0x01;
inline constexpr std::size_t kOutputReportSize = 49;
inline constexpr std::uint8_t kSubcommandSetInputMode = 0x03;
inline constexpr std::uint8_t kSubcommandSpiRead = 0x10;
inline constexpr std::uint32_t kFactoryStickCalAddress = 0x603D;
inline constexpr std::size_t kFactoryStickCalSize = 18;
inline constexpr std::size_t kReplySubcommand = 14, kReplySpiAddress = 15, kReplySpiSize = 19, kReplySpiData = 20;
inline constexpr std::uint8_t kUsbCommand = 0x80, kUsbHandshake = 0x02, kUsbForceHid = 0x04;

struct StickCalibration {
    std::int32_t centre_x, centre_y;
    std::int32_t x_below, x_above;  // raw counts from centre to the left / right end
    std::int32_t y_below, y_above;  // to the bottom / top end
};
struct Calibration {
    StickCalibration left, right;
    bool from_device = false;
};
// When the flash cannot be read: centre 2048, 1536 counts to every side (a
// little inside the 12-bit range, as real sticks reach about ±1500-1700).
inline constexpr StickCalibration kDefaultStick = {2048, 2048, 1536, 1536, 1536, 1536};
inline constexpr Calibration kDefaultCalibration = {kDefaultStick, kDefaultStick, false};

// Decodes the 18-byte factory block. False (and `out` untouched) when a stick's
// block is unprogrammed (all 0xFF) or holds zero ranges.
bool decode_factory_calibration(std::span<const std::uint8_t> block, Calibration& out);
// The inverse, for firmware_sim.
std::array<std::uint8_t, kFactoryStickCalSize> encode_factory_calibration(const Calibration& cal);

// Builds the subcommand output report; `counter` is the 4-bit packet number.
std::array<std::uint8_t, kOutputReportSize> make_subcommand(std::uint8_t counter, std::uint8_t subcommand,
                                                            std::span<const std::uint8_t> args);

ParseStatus parse(std::span<const std::uint8_t> report, const Calibration& cal, InputSample& out);

}  // namespace marionette::input::switchpro
