#include "input/hid/steam_deck.hpp"

namespace marionette::input::steamdeck {

std::array<std::uint8_t, kFeatureReportSize> clear_digital_mappings_report() {
    std::array<std::uint8_t, kFeatureReportSize> r{};
    r[1] = kClearDigitalMappings;
    return r;
}

std::array<std::uint8_t, kFeatureReportSize> disable_lizard_settings_report() {
    std::array<std::uint8_t, kFeatureReportSize> r{};
    r[1] = kSetSettingsValues;
    struct Setting { std::uint8_t number; std::uint16_t value; };
    static constexpr Setting kSettings[] = {
        {kSettingSmoothAbsoluteMouse, 0},
        {kSettingLeftTrackpadMode, kTrackpadNone},
        {kSettingRightTrackpadMode, kTrackpadNone},
        {kSettingLeftClickPressure, 0xFFFF},
        {kSettingRightClickPressure, 0xFFFF},
    };
    std::size_t at = 3;
    for (const Setting& s : kSettings) {
        r[at++] = s.number;
        r[at++] = static_cast<std::uint8_t>(s.value & 0xFF);
        r[at++] = static_cast<std::uint8_t>(s.value >> 8);
    }
    r[2] = static_cast<std::uint8_t>(at - 3);  // payload length
    return r;
}

ParseStatus parse(std::span<const std::uint8_t> r, InputSample& out) {
    if (r.size() < kReportSize) return ParseStatus::too_short;
    if (r.size() > kReportSize) return ParseStatus::too_long;
    if (read_u16le(r, kVersion) != kReportVersion || r[kLength] != kReportSize) return ParseStatus::garbled;
    if (r[kType] != kTypeDeckState) return ParseStatus::ignored;  // other message types carry no state
    const std::uint32_t lo = read_u32le(r, kButtonsLow);
    std::uint32_t buttons = 0;
    if (lo & kA) buttons |= button_bit(Button::south);
    if (lo & kB) buttons |= button_bit(Button::east);
    if (lo & kX) buttons |= button_bit(Button::west);
    if (lo & kY) buttons |= button_bit(Button::north);
    if (lo & kL1) buttons |= button_bit(Button::left_shoulder);
    if (lo & kR1) buttons |= button_bit(Button::right_shoulder);
    if (lo & kView) buttons |= button_bit(Button::back);
    if (lo & kMenu) buttons |= button_bit(Button::start);
    if (lo & kSteam) buttons |= button_bit(Button::guide);
    if (lo & kL3) buttons |= button_bit(Button::left_stick);
    if (lo & kR3) buttons |= button_bit(Button::right_stick);
    if (lo & kDpadUp) buttons |= button_bit(Button::dpad_up);
    if (lo & kDpadDown) buttons |= button_bit(Button::dpad_down);
    if (lo & kDpadLeft) buttons |= button_bit(Button::dpad_left);
    if (lo & kDpadRight) buttons |= button_bit(Button::dpad_right);
    out.lx = normalise_centred(read_s16le(r, kLeftStickX), -32768, 32767);
    out.ly = normalise_centred(read_s16le(r, kLeftStickY), -32768, 32767);
    out.rx = normalise_centred(read_s16le(r, kRightStickX), -32768, 32767);
    out.ry = normalise_centred(read_s16le(r, kRightStickY), -32768, 32767);
    out.lt = normalise_trigger(read_u16le(r, kLeftTrigger), 0, 32767);
    out.rt = normalise_trigger(read_u16le(r, kRightTrigger), 0, 32767);
    out.buttons = buttons;
    out.has_device_counter = true;
    out.device_counter = read_u32le(r, kPacketNumber);
    return ParseStatus::ok;
}

}  // namespace marionette::input::steamdeck
