#include "firmware_sim/report_encoders.hpp"

#include <algorithm>
#include <cmath>

#include "input/hid/ds4.hpp"
#include "input/hid/dualsense.hpp"
#include "input/hid/steam_deck.hpp"

namespace marionette::firmware_sim {

using namespace marionette::input;

namespace {
std::uint8_t dpad_to_hat(std::uint32_t b) {
    const bool up = b & button_bit(Button::dpad_up), down = b & button_bit(Button::dpad_down);
    const bool left = b & button_bit(Button::dpad_left), right = b & button_bit(Button::dpad_right);
    if (up && right) return 1;
    if (down && right) return 3;
    if (down && left) return 5;
    if (up && left) return 7;
    if (up) return 0;
    if (right) return 2;
    if (down) return 4;
    if (left) return 6;
    return 8;
}
bool has(std::uint32_t b, Button button) { return (b & button_bit(button)) != 0; }
void put_u16(std::uint8_t* p, std::uint16_t v) { p[0] = static_cast<std::uint8_t>(v); p[1] = static_cast<std::uint8_t>(v >> 8); }
void put_u32(std::uint8_t* p, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void pack12(std::uint8_t* out, std::int32_t lo, std::int32_t hi) {
    out[0] = static_cast<std::uint8_t>(lo & 0xFF);
    out[1] = static_cast<std::uint8_t>(((lo >> 8) & 0x0F) | ((hi & 0x0F) << 4));
    out[2] = static_cast<std::uint8_t>((hi >> 4) & 0xFF);
}
std::uint8_t sony_buttons0(const PadState& s) {
    std::uint8_t b = dpad_to_hat(s.buttons);
    if (has(s.buttons, Button::west)) b |= kSonySquare;
    if (has(s.buttons, Button::south)) b |= kSonyCross;
    if (has(s.buttons, Button::east)) b |= kSonyCircle;
    if (has(s.buttons, Button::north)) b |= kSonyTriangle;
    return b;
}
std::uint8_t sony_buttons1(const PadState& s) {
    std::uint8_t b = 0;
    if (has(s.buttons, Button::left_shoulder)) b |= kSonyL1;
    if (has(s.buttons, Button::right_shoulder)) b |= kSonyR1;
    if (s.lt > 0.0) b |= kSonyL2;  // the digital bit follows the analogue trigger
    if (s.rt > 0.0) b |= kSonyR2;
    if (has(s.buttons, Button::back)) b |= kSonyShare;
    if (has(s.buttons, Button::start)) b |= kSonyOptions;
    if (has(s.buttons, Button::left_stick)) b |= kSonyL3;
    if (has(s.buttons, Button::right_stick)) b |= kSonyR3;
    return b;
}
// The report id, size, sticks, triggers and face/shoulder buttons at `layout`'s
// offsets; returns where the USB offsets start (after the Bluetooth shift).
std::uint8_t* encode_sony_fields(const PadState& s, const SonyReportLayout& layout, bool bluetooth, Report& r) {
    r.size = bluetooth ? layout.bt_report_size : layout.usb_report_size;
    r.bytes[0] = bluetooth ? layout.bt_report_id : layout.usb_report_id;
    std::uint8_t* p = r.bytes.data() + (bluetooth ? layout.bt_shift : 0);
    p[layout.left_x] = encode_centred8(s.lx);
    p[layout.left_y] = encode_centred8(-s.ly);
    p[layout.right_x] = encode_centred8(s.rx);
    p[layout.right_y] = encode_centred8(-s.ry);
    p[layout.left_trigger] = static_cast<std::uint8_t>(encode_trigger(s.lt, 0, 255));
    p[layout.right_trigger] = static_cast<std::uint8_t>(encode_trigger(s.rt, 0, 255));
    p[layout.buttons0] = sony_buttons0(s);
    p[layout.buttons1] = sony_buttons1(s);
    return p;
}
void seal_bluetooth(Report& r, const SonyReportLayout& layout) {
    put_u32(&r.bytes[layout.bt_crc_offset],
            sony_bt_crc32(layout.bt_crc_seed, std::span<const std::uint8_t>(r.bytes.data(), layout.bt_crc_offset)));
}
}  // namespace

std::int32_t encode_centred(double v, std::int32_t min, std::int32_t max) {
    v = std::clamp(v, -1.0, 1.0);
    const std::int64_t centre = static_cast<std::int64_t>(min) + (static_cast<std::int64_t>(max) - min + 1) / 2;
    const double span = v >= 0 ? static_cast<double>(max - centre) : static_cast<double>(centre - min);
    return static_cast<std::int32_t>(centre + std::llround(v * span));
}
std::int32_t encode_trigger(double v, std::int32_t min, std::int32_t max) {
    v = std::clamp(v, 0.0, 1.0);
    return static_cast<std::int32_t>(min + std::llround(v * (static_cast<double>(max) - min)));
}
std::uint8_t encode_centred8(double v) { return static_cast<std::uint8_t>(encode_centred(v, 0, 255)); }
std::int16_t encode_s16(double v) { return static_cast<std::int16_t>(encode_centred(v, -32768, 32767)); }

Report encode_ds4(const PadState& s, const ReportClock& clock, bool bluetooth) {
    Report r;
    std::uint8_t* p = encode_sony_fields(s, ds4::kLayout, bluetooth, r);
    if (bluetooth) r.bytes[1] = 0xC0;  // HID + CRC flags, as the pad sends
    p[ds4::kLayout.buttons2] = static_cast<std::uint8_t>(((clock.counter & 0x3F) << ds4::kLayout.counter_shift) |
                                                         (has(s.buttons, Button::guide) ? kSonyPs : 0));
    put_u16(p + ds4::kTimestamp, static_cast<std::uint16_t>(clock.device_time_us * 3 / 16));  // 5.33 µs units
    if (bluetooth) seal_bluetooth(r, ds4::kLayout);
    return r;
}

Report encode_dualsense(const PadState& s, const ReportClock& clock, bool bluetooth) {
    Report r;
    std::uint8_t* p = encode_sony_fields(s, dualsense::kLayout, bluetooth, r);
    p[dualsense::kLayout.counter] = static_cast<std::uint8_t>(clock.counter);
    p[dualsense::kLayout.buttons2] = has(s.buttons, Button::guide) ? kSonyPs : 0;
    put_u32(p + dualsense::kSensorTimestamp, static_cast<std::uint32_t>(clock.device_time_us * 3));  // 0.33 µs units
    if (bluetooth) seal_bluetooth(r, dualsense::kLayout);
    return r;
}

Report encode_switchpro(const PadState& s, const ReportClock& clock, const switchpro::Calibration& cal) {
    Report r;
    r.size = switchpro::kUsbReportSize;
    r.bytes[0] = switchpro::kFullReportId;
    r.bytes[switchpro::kTimer] = static_cast<std::uint8_t>(clock.counter);
    r.bytes[2] = 0x8E;  // battery full, USB powered
    std::uint8_t right = 0, shared = 0, left = 0;
    if (has(s.buttons, Button::south)) right |= switchpro::kB;
    if (has(s.buttons, Button::east)) right |= switchpro::kA;
    if (has(s.buttons, Button::west)) right |= switchpro::kY;
    if (has(s.buttons, Button::north)) right |= switchpro::kX;
    if (has(s.buttons, Button::right_shoulder)) right |= switchpro::kR;
    if (s.rt >= 0.5) right |= switchpro::kZR;
    if (has(s.buttons, Button::back)) shared |= switchpro::kMinus;
    if (has(s.buttons, Button::start)) shared |= switchpro::kPlus;
    if (has(s.buttons, Button::guide)) shared |= switchpro::kHome;
    if (has(s.buttons, Button::left_stick)) shared |= switchpro::kLStick;
    if (has(s.buttons, Button::right_stick)) shared |= switchpro::kRStick;
    if (has(s.buttons, Button::left_shoulder)) left |= switchpro::kL;
    if (s.lt >= 0.5) left |= switchpro::kZL;
    if (has(s.buttons, Button::dpad_up)) left |= switchpro::kUp;
    if (has(s.buttons, Button::dpad_down)) left |= switchpro::kDown;
    if (has(s.buttons, Button::dpad_left)) left |= switchpro::kLeft;
    if (has(s.buttons, Button::dpad_right)) left |= switchpro::kRight;
    r.bytes[switchpro::kButtonsRight] = right;
    r.bytes[switchpro::kButtonsShared] = shared;
    r.bytes[switchpro::kButtonsLeft] = left;
    const auto raw = [](double v, std::int32_t centre, std::int32_t below, std::int32_t above) {
        v = std::clamp(v, -1.0, 1.0);
        const std::int64_t out = centre + std::llround(v * (v >= 0 ? above : below));
        return static_cast<std::int32_t>(std::clamp<std::int64_t>(out, 0, 4095));
    };
    pack12(&r.bytes[switchpro::kLeftStick], raw(s.lx, cal.left.centre_x, cal.left.x_below, cal.left.x_above),
           raw(s.ly, cal.left.centre_y, cal.left.y_below, cal.left.y_above));
    pack12(&r.bytes[switchpro::kRightStick], raw(s.rx, cal.right.centre_x, cal.right.x_below, cal.right.x_above),
           raw(s.ry, cal.right.centre_y, cal.right.y_below, cal.right.y_above));
    return r;
}

Report encode_steamdeck(const PadState& s, const ReportClock& clock) {
    Report r;
    r.size = steamdeck::kReportSize;
    put_u16(&r.bytes[steamdeck::kVersion], steamdeck::kReportVersion);
    r.bytes[steamdeck::kType] = steamdeck::kTypeDeckState;
    r.bytes[steamdeck::kLength] = static_cast<std::uint8_t>(steamdeck::kReportSize);
    put_u32(&r.bytes[steamdeck::kPacketNumber], clock.counter);
    std::uint32_t lo = 0;
    if (has(s.buttons, Button::south)) lo |= steamdeck::kA;
    if (has(s.buttons, Button::east)) lo |= steamdeck::kB;
    if (has(s.buttons, Button::west)) lo |= steamdeck::kX;
    if (has(s.buttons, Button::north)) lo |= steamdeck::kY;
    if (has(s.buttons, Button::left_shoulder)) lo |= steamdeck::kL1;
    if (has(s.buttons, Button::right_shoulder)) lo |= steamdeck::kR1;
    if (has(s.buttons, Button::back)) lo |= steamdeck::kView;
    if (has(s.buttons, Button::start)) lo |= steamdeck::kMenu;
    if (has(s.buttons, Button::guide)) lo |= steamdeck::kSteam;
    if (has(s.buttons, Button::left_stick)) lo |= steamdeck::kL3;
    if (has(s.buttons, Button::right_stick)) lo |= steamdeck::kR3;
    if (has(s.buttons, Button::dpad_up)) lo |= steamdeck::kDpadUp;
    if (has(s.buttons, Button::dpad_down)) lo |= steamdeck::kDpadDown;
    if (has(s.buttons, Button::dpad_left)) lo |= steamdeck::kDpadLeft;
    if (has(s.buttons, Button::dpad_right)) lo |= steamdeck::kDpadRight;
    if (s.lt >= 0.9) lo |= steamdeck::kL2;
    if (s.rt >= 0.9) lo |= steamdeck::kR2;
    put_u32(&r.bytes[steamdeck::kButtonsLow], lo);
    put_u16(&r.bytes[steamdeck::kLeftTrigger], static_cast<std::uint16_t>(encode_trigger(s.lt, 0, 32767)));
    put_u16(&r.bytes[steamdeck::kRightTrigger], static_cast<std::uint16_t>(encode_trigger(s.rt, 0, 32767)));
    put_u16(&r.bytes[steamdeck::kLeftStickX], static_cast<std::uint16_t>(encode_s16(s.lx)));
    put_u16(&r.bytes[steamdeck::kLeftStickY], static_cast<std::uint16_t>(encode_s16(s.ly)));
    put_u16(&r.bytes[steamdeck::kRightStickX], static_cast<std::uint16_t>(encode_s16(s.rx)));
    put_u16(&r.bytes[steamdeck::kRightStickY], static_cast<std::uint16_t>(encode_s16(s.ry)));
    return r;
}

Report encode_report(HidFormat format, const PadState& s, const ReportClock& clock, bool bluetooth,
                     const switchpro::Calibration& cal) {
    switch (format) {
        case HidFormat::ds4: return encode_ds4(s, clock, bluetooth);
        case HidFormat::dualsense: return encode_dualsense(s, clock, bluetooth);
        case HidFormat::switchpro: return encode_switchpro(s, clock, cal);
        case HidFormat::steamdeck: return encode_steamdeck(s, clock);
    }
    return {};
}

}  // namespace marionette::firmware_sim
