#pragma once
// The report layout the DualShock 4 and the DualSense share: one USB report and
// one longer Bluetooth report carrying the same fields `bt_shift` bytes later and
// ending in a CRC-32; sticks and triggers as bytes; face, shoulder and stick
// buttons with the same bits, the hat in the low nibble of the first button byte.
// Only the offsets differ, so each pad describes its layout and this parses it.
#include <cstddef>
#include <cstdint>
#include <span>

#include "input/hid/hid_report.hpp"

namespace marionette::input {

struct SonyReportLayout {
    std::uint8_t usb_report_id = 0;
    std::size_t usb_report_size = 0;
    std::uint8_t bt_report_id = 0;
    std::size_t bt_report_size = 0;
    std::size_t bt_shift = 0;        // BT offset = USB offset + bt_shift
    std::size_t bt_crc_offset = 0;   // CRC-32 (LE) over the seed byte and bytes 0 … offset−1
    std::uint8_t bt_crc_seed = 0;
    std::size_t left_x = 0, left_y = 0, right_x = 0, right_y = 0;  // USB offsets, 0..255, y down
    std::size_t left_trigger = 0, right_trigger = 0;
    std::size_t buttons0 = 0;  // hat bits 0-3; square 4, cross 5, circle 6, triangle 7
    std::size_t buttons1 = 0;  // L1 0, R1 1, L2 2, R2 3, share/create 4, options 5, L3 6, R3 7
    std::size_t buttons2 = 0;  // PS 0, touchpad 1
    std::size_t counter = 0;   // byte holding the report counter …
    int counter_shift = 0;     // … in its bits counter_shift and up
};

// Button bits common to both pads.
inline constexpr std::uint8_t kSonyHatMask = 0x0F;
inline constexpr std::uint8_t kSonySquare = 0x10, kSonyCross = 0x20, kSonyCircle = 0x40, kSonyTriangle = 0x80;
inline constexpr std::uint8_t kSonyL1 = 0x01, kSonyR1 = 0x02, kSonyL2 = 0x04, kSonyR2 = 0x08, kSonyShare = 0x10,
                              kSonyOptions = 0x20, kSonyL3 = 0x40, kSonyR3 = 0x80;
inline constexpr std::uint8_t kSonyPs = 0x01, kSonyTouchpad = 0x02;

// USB or Bluetooth report (length exact, Bluetooth CRC checked).
ParseStatus parse_sony_report(std::span<const std::uint8_t> report, const SonyReportLayout& layout, InputSample& out);

}  // namespace marionette::input
