#include "input/hid/hid_report.hpp"

#include <array>

namespace marionette::input {

namespace {
constexpr std::array<std::string_view, kHidFormatCount> kNames = {"ds4", "dualsense", "switchpro", "steamdeck"};

constexpr HidDeviceKind kDevices[] = {
    {0x054c, 0x05c4, HidFormat::ds4, -1, "Sony DualShock 4 (CUH-ZCT1)"},
    {0x054c, 0x09cc, HidFormat::ds4, -1, "Sony DualShock 4 (CUH-ZCT2)"},
    {0x054c, 0x0ba0, HidFormat::ds4, -1, "Sony DualShock 4 USB wireless adaptor"},
    {0x054c, 0x0ce6, HidFormat::dualsense, -1, "Sony DualSense"},
    {0x054c, 0x0df2, HidFormat::dualsense, -1, "Sony DualSense Edge"},
    {0x057e, 0x2009, HidFormat::switchpro, -1, "Nintendo Switch Pro Controller"},
    // The Deck's controls enumerate as several interfaces; the gamepad reports come on 2.
    {0x28de, 0x1205, HidFormat::steamdeck, 2, "Steam Deck controls"},
};

std::array<std::uint32_t, 256> make_crc_table() {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
        std::uint32_t c = i;
        for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
        t[i] = c;
    }
    return t;
}
const std::array<std::uint32_t, 256> kCrcTable = make_crc_table();
}  // namespace

std::string_view hid_format_name(HidFormat f) { return kNames[static_cast<std::size_t>(f)]; }

std::optional<HidFormat> hid_format_from_name(std::string_view name) {
    for (std::size_t i = 0; i < kNames.size(); ++i)
        if (kNames[i] == name) return static_cast<HidFormat>(i);
    return std::nullopt;
}

std::string_view parse_status_name(ParseStatus s) {
    switch (s) {
        case ParseStatus::ok: return "ok";
        case ParseStatus::too_short: return "too short";
        case ParseStatus::too_long: return "too long";
        case ParseStatus::wrong_report_id: return "wrong report id";
        case ParseStatus::garbled: return "garbled";
        case ParseStatus::ignored: return "ignored";
    }
    return "?";
}

bool hat_to_dpad(std::uint8_t hat, std::uint32_t& buttons) {
    // Bits per direction: up, right, down, left.
    static constexpr std::uint8_t kDirections[8] = {0b0001, 0b0011, 0b0010, 0b0110, 0b0100, 0b1100, 0b1000, 0b1001};
    if (hat == 8) return true;
    if (hat > 8) return false;
    const std::uint8_t d = kDirections[hat];
    if (d & 0b0001) buttons |= button_bit(Button::dpad_up);
    if (d & 0b0010) buttons |= button_bit(Button::dpad_right);
    if (d & 0b0100) buttons |= button_bit(Button::dpad_down);
    if (d & 0b1000) buttons |= button_bit(Button::dpad_left);
    return true;
}

std::uint32_t sony_bt_crc32(std::uint8_t seed, std::span<const std::uint8_t> data) {
    std::uint32_t c = 0xFFFFFFFFu;
    c = kCrcTable[(c ^ seed) & 0xFF] ^ (c >> 8);
    for (const std::uint8_t b : data) c = kCrcTable[(c ^ b) & 0xFF] ^ (c >> 8);
    return c ^ 0xFFFFFFFFu;
}

std::span<const HidDeviceKind> supported_hid_devices() { return kDevices; }

std::optional<HidDeviceKind> find_hid_device_kind(std::uint16_t vendor, std::uint16_t product, int interface_number) {
    for (const HidDeviceKind& k : kDevices)
        if (k.vendor_id == vendor && k.product_id == product &&
            (k.interface_number < 0 || interface_number < 0 || k.interface_number == interface_number))
            return k;
    return std::nullopt;
}

}  // namespace marionette::input
