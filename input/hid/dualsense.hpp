#pragma once
// Sony DualSense input reports (references: the kernel's hid-playstation
// struct dualsense_input_report, SDL2's SDL_hidapi_ps5.c). Offsets are in the
// USB report 0x01, report id at 0; the Bluetooth report 0x31 carries the same
// fields one byte later and ends in a CRC-32.
#include <cstddef>
#include <cstdint>
#include <span>

#include "input/hid/hid_report.hpp"

namespace marionette::input::dualsense {

inline constexpr std::uint8_t kUsbReportId = 0x01;
inline constexpr std::size_t kUsbReportSize = 64;
inline constexpr std::uint8_t kBtReportId = 0x31;
inline constexpr std::size_t kBtReportSize = 78;
inline constexpr std::size_t kBtShift = 1;
inline constexpr std::size_t kBtCrcOffset = 74;
inline constexpr std::uint8_t kBtCrcSeed = 0xA1;

inline constexpr std::size_t kLeftX = 1, kLeftY = 2, kRightX = 3, kRightY = 4;  // 0..255, y down
inline constexpr std::size_t kLeftTrigger = 5, kRightTrigger = 6;                // 0..255
inline constexpr std::size_t kSequence = 7;
inline constexpr std::size_t kButtons0 = 8;  // hat bits 0-3; square 4, cross 5, circle 6, triangle 7
inline constexpr std::size_t kButtons1 = 9;  // L1 0, R1 1, L2 2, R2 3, create 4, options 5, L3 6, R3 7
inline constexpr std::size_t kButtons2 = 10; // PS 0, touchpad 1, mute 2
inline constexpr std::size_t kSensorTimestamp = 28;  // u32 LE, 0.33 µs units

inline constexpr std::uint8_t kHatMask = 0x0F;
inline constexpr std::uint8_t kSquare = 0x10, kCross = 0x20, kCircle = 0x40, kTriangle = 0x80;
inline constexpr std::uint8_t kL1 = 0x01, kR1 = 0x02, kL2 = 0x04, kR2 = 0x08, kCreate = 0x10, kOptions = 0x20,
                              kL3 = 0x40, kR3 = 0x80;
inline constexpr std::uint8_t kPs = 0x01, kTouchpad = 0x02, kMute = 0x04;

ParseStatus parse(std::span<const std::uint8_t> report, InputSample& out);

}  // namespace marionette::input::dualsense
