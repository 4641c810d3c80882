#pragma once
// Sony DualSense input reports (references: the kernel's hid-playstation
// struct dualsense_input_report, SDL2's SDL_hidapi_ps5.c). Offsets are in the
// USB report 0x01, report id at 0; the Bluetooth report 0x31 carries the same
// fields one byte later and ends in a CRC-32. The button bits are the ones both
// Sony pads share (sony_report.hpp), plus mute.
#include <cstddef>
#include <cstdint>
#include <span>

#include "input/hid/hid_report.hpp"
#include "input/hid/sony_report.hpp"

namespace marionette::input::dualsense {

inline constexpr SonyReportLayout kLayout{
    .usb_report_id = 0x01, .usb_report_size = 64, .bt_report_id = 0x31, .bt_report_size = 78,
    .bt_shift = 1,        // BT offset = USB offset + 1
    .bt_crc_offset = 74,  // CRC-32 (LE) over 0xA1 and bytes 0..73
    .bt_crc_seed = 0xA1,
    .left_x = 1, .left_y = 2, .right_x = 3, .right_y = 4,  // 0..255, y down
    .left_trigger = 5, .right_trigger = 6,                 // 0..255
    .buttons0 = 8,   // hat bits 0-3; square 4, cross 5, circle 6, triangle 7
    .buttons1 = 9,   // L1 0, R1 1, L2 2, R2 3, create 4, options 5, L3 6, R3 7
    .buttons2 = 10,  // PS 0, touchpad 1, mute 2
    .counter = 7, .counter_shift = 0,  // the whole byte is a sequence number
};
inline constexpr std::size_t kSensorTimestamp = 28;  // u32 LE, 0.33 µs units
inline constexpr std::uint8_t kMute = 0x04;          // in buttons2

ParseStatus parse(std::span<const std::uint8_t> report, InputSample& out);

}  // namespace marionette::input::dualsense
