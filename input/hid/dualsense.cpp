#include "input/hid/dualsense.hpp"

namespace marionette::input::dualsense {

ParseStatus parse(std::span<const std::uint8_t> r, InputSample& out) {
    if (r.empty()) return ParseStatus::too_short;
    std::size_t shift = 0;
    if (r[0] == kUsbReportId) {
        if (r.size() < kUsbReportSize) return ParseStatus::too_short;
        if (r.size() > kUsbReportSize) return ParseStatus::too_long;
    } else if (r[0] == kBtReportId) {
        if (r.size() < kBtReportSize) return ParseStatus::too_short;
        if (r.size() > kBtReportSize) return ParseStatus::too_long;
        if (sony_bt_crc32(kBtCrcSeed, r.first(kBtCrcOffset)) != read_u32le(r, kBtCrcOffset)) return ParseStatus::garbled;
        shift = kBtShift;
    } else {
        return ParseStatus::wrong_report_id;
    }
    const auto at = [&](std::size_t usb_offset) { return r[usb_offset + shift]; };
    std::uint32_t buttons = 0;
    if (!hat_to_dpad(at(kButtons0) & kHatMask, buttons)) return ParseStatus::garbled;
    const std::uint8_t b0 = at(kButtons0), b1 = at(kButtons1), b2 = at(kButtons2);
    if (b0 & kCross) buttons |= button_bit(Button::south);
    if (b0 & kCircle) buttons |= button_bit(Button::east);
    if (b0 & kSquare) buttons |= button_bit(Button::west);
    if (b0 & kTriangle) buttons |= button_bit(Button::north);
    if (b1 & kL1) buttons |= button_bit(Button::left_shoulder);
    if (b1 & kR1) buttons |= button_bit(Button::right_shoulder);
    if (b1 & kCreate) buttons |= button_bit(Button::back);
    if (b1 & kOptions) buttons |= button_bit(Button::start);
    if (b1 & kL3) buttons |= button_bit(Button::left_stick);
    if (b1 & kR3) buttons |= button_bit(Button::right_stick);
    if (b2 & kPs) buttons |= button_bit(Button::guide);

    out.lx = normalise_centred(at(kLeftX), 0, 255);
    out.ly = flip_axis(normalise_centred(at(kLeftY), 0, 255));
    out.rx = normalise_centred(at(kRightX), 0, 255);
    out.ry = flip_axis(normalise_centred(at(kRightY), 0, 255));
    out.lt = normalise_trigger(at(kLeftTrigger), 0, 255);
    out.rt = normalise_trigger(at(kRightTrigger), 0, 255);
    out.buttons = buttons;
    out.has_device_counter = true;
    out.device_counter = at(kSequence);
    return ParseStatus::ok;
}

}  // namespace marionette::input::dualsense
