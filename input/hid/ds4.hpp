#pragma once
// Sony DualShock 4 input reports (references: the kernel's hid-playstation,
// SDL2's SDL_hidapi_ps4.c). Offsets are in the USB report 0x01, report id at 0;
// the Bluetooth report 0x11 carries the same fields two bytes later and ends in
// a CRC-32. The button bits are the ones both Sony pads share (sony_report.hpp).
#include <cstddef>
#include <cstdint>
#include <span>

#include "input/hid/hid_report.hpp"
#include "input/hid/sony_report.hpp"

namespace marionette::input::ds4 {

inline constexpr SonyReportLayout kLayout{
    .usb_report_id = 0x01, .usb_report_size = 64, .bt_report_id = 0x11, .bt_report_size = 78,
    .bt_shift = 2,        // BT offset = USB offset + 2
    .bt_crc_offset = 74,  // CRC-32 (LE) over 0xA1 and bytes 0..73
    .bt_crc_seed = 0xA1,
    .left_x = 1, .left_y = 2, .right_x = 3, .right_y = 4,  // 0..255, y down
    .left_trigger = 8, .right_trigger = 9,                 // 0..255
    .buttons0 = 5,  // hat in bits 0-3; square 4, cross 5, circle 6, triangle 7
    .buttons1 = 6,  // L1 0, R1 1, L2 2, R2 3, share 4, options 5, L3 6, R3 7
    .buttons2 = 7,  // PS 0, touchpad click 1, report counter in bits 2-7
    .counter = 7, .counter_shift = 2,
};
inline constexpr std::size_t kTimestamp = 10;  // u16 LE, units of 5.33 µs

// USB (64 bytes, id 0x01) or Bluetooth (78 bytes, id 0x11, CRC checked).
ParseStatus parse(std::span<const std::uint8_t> report, InputSample& out);

}  // namespace marionette::input::ds4
