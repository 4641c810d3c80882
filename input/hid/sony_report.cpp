#include "input/hid/sony_report.hpp"

namespace marionette::input {

ParseStatus parse_sony_report(std::span<const std::uint8_t> r, const SonyReportLayout& layout, InputSample& out) {
    if (r.empty()) return ParseStatus::too_short;
    std::size_t shift = 0;
    if (r[0] == layout.usb_report_id) {
        if (r.size() < layout.usb_report_size) return ParseStatus::too_short;
        if (r.size() > layout.usb_report_size) return ParseStatus::too_long;
    } else if (r[0] == layout.bt_report_id) {
        if (r.size() < layout.bt_report_size) return ParseStatus::too_short;
        if (r.size() > layout.bt_report_size) return ParseStatus::too_long;
        if (sony_bt_crc32(layout.bt_crc_seed, r.first(layout.bt_crc_offset)) != read_u32le(r, layout.bt_crc_offset))
            return ParseStatus::garbled;
        shift = layout.bt_shift;
    } else {
        return ParseStatus::wrong_report_id;
    }
    const auto at = [&](std::size_t usb_offset) { return r[usb_offset + shift]; };
    std::uint32_t buttons = 0;
    if (!hat_to_dpad(at(layout.buttons0) & kSonyHatMask, buttons)) return ParseStatus::garbled;
    const std::uint8_t b0 = at(layout.buttons0), b1 = at(layout.buttons1), b2 = at(layout.buttons2);
    if (b0 & kSonyCross) buttons |= button_bit(Button::south);
    if (b0 & kSonyCircle) buttons |= button_bit(Button::east);
    if (b0 & kSonySquare) buttons |= button_bit(Button::west);
    if (b0 & kSonyTriangle) buttons |= button_bit(Button::north);
    if (b1 & kSonyL1) buttons |= button_bit(Button::left_shoulder);
    if (b1 & kSonyR1) buttons |= button_bit(Button::right_shoulder);
    if (b1 & kSonyShare) buttons |= button_bit(Button::back);
    if (b1 & kSonyOptions) buttons |= button_bit(Button::start);
    if (b1 & kSonyL3) buttons |= button_bit(Button::left_stick);
    if (b1 & kSonyR3) buttons |= button_bit(Button::right_stick);
    if (b2 & kSonyPs) buttons |= button_bit(Button::guide);

    out.lx = normalise_centred(at(layout.left_x), 0, 255);
    out.ly = flip_axis(normalise_centred(at(layout.left_y), 0, 255));
    out.rx = normalise_centred(at(layout.right_x), 0, 255);
    out.ry = flip_axis(normalise_centred(at(layout.right_y), 0, 255));
    out.lt = normalise_trigger(at(layout.left_trigger), 0, 255);
    out.rt = normalise_trigger(at(layout.right_trigger), 0, 255);
    out.buttons = buttons;
    out.has_device_counter = true;
    out.device_counter = static_cast<std::uint32_t>(at(layout.counter) >> layout.counter_shift);
    return ParseStatus::ok;
}

}  // namespace marionette::input
