#pragma once
// Sony DualShock 4 input reports (references: the kernel's hid-playstation,
// SDL2's SDL_hidapi_ps4.c). Offsets are in the USB report 0x01, report id at 0;
// the Bluetooth report 0x11 carries the same fields two bytes later and ends in
// a CRC-32.
#include <cstddef>
#include <cstdint>
#include <span>

#include "input/hid/hid_report.hpp"

namespace marionette::input::ds4 {

inline constexpr std::uint8_t kUsbReportId = 0x01;
inline constexpr std::size_t kUsbReportSize = 64;
inline constexpr std::uint8_t kBtReportId = 0x11;
inline constexpr std::size_t kBtReportSize = 78;
inline constexpr std::size_t kBtShift = 2;        // BT offset = USB offset + 2
inline constexpr std::size_t kBtCrcOffset = 74;   // CRC-32 (LE) over 0xA1 and bytes 0..73
inline constexpr std::uint8_t kBtCrcSeed = 0xA1;

inline constexpr std::size_t kLeftX = 1, kLeftY = 2, kRightX = 3, kRightY = 4;  // 0..255, y down
inline constexpr std::size_t kButtons0 = 5;  // hat in bits 0-3; square 4, cross 5, circle 6, triangle 7
inline constexpr std::size_t kButtons1 = 6;  // L1 0, R1 1, L2 2, R2 3, share 4, options 5, L3 6, R3 7
inline constexpr std::size_t kButtons2 = 7;  // PS 0, touchpad click 1, report counter in bits 2-7
inline constexpr std::size_t kLeftTrigger = 8, kRightTrigger = 9;  // 0..255
inline constexpr std::size_t kTimestamp = 10;  // u16 LE, units of 5.33 µs

inline constexpr std::uint8_t kHatMask = 0x0F;
inline constexpr std::uint8_t kSquare = 0x10, kCross = 0x20, kCircle = 0x40, kTriangle = 0x80;
inline constexpr std::uint8_t kL1 = 0x01, kR1 = 0x02, kL2 = 0x04, kR2 = 0x08, kShare = 0x10, kOptions = 0x20,
                              kL3 = 0x40, kR3 = 0x80;
inline constexpr std::uint8_t kPs = 0x01, kTouchpad = 0x02;
inline constexpr int kCounterShift = 2;

// USB (64 bytes, id 0x01) or Bluetooth (78 bytes, id 0x11, CRC checked).
ParseStatus parse(std::span<const std::uint8_t> report, InputSample& out);

}  // namespace marionette::input::ds4
