#pragma once
// Raw HID report formats marionette reads byte-exactly (one file per family:
// ds4, dualsense, switch_pro, steam_deck), the status every parser returns, and
// the counters of rejected reports. Parsers never read past the span they are
// given and never allocate: they validate length, report id and header first.
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "input/input_sample.hpp"

namespace marionette::input {

enum class HidFormat : std::uint8_t { ds4, dualsense, switchpro, steamdeck };
inline constexpr int kHidFormatCount = 4;
std::string_view hid_format_name(HidFormat format);
std::optional<HidFormat> hid_format_from_name(std::string_view name);

enum class ParseStatus : std::uint8_t {
    ok,
    too_short,        // fewer bytes than the report needs
    too_long,         // more bytes than the report has (a merged or garbled read)
    wrong_report_id,  // not an input report of this format
    garbled,          // right size and id, but a field holds an impossible value or the CRC fails
    ignored,          // a valid report that carries no controller state (e.g. a reply)
};
std::string_view parse_status_name(ParseStatus status);

struct ParseCounters {
    std::uint64_t accepted = 0;
    std::uint64_t ignored = 0;
    std::uint64_t too_short = 0;
    std::uint64_t too_long = 0;
    std::uint64_t wrong_report_id = 0;
    std::uint64_t garbled = 0;
    std::uint64_t rejected() const { return too_short + too_long + wrong_report_id + garbled; }
    void count(ParseStatus s) {
        switch (s) {
            case ParseStatus::ok: ++accepted; break;
            case ParseStatus::ignored: ++ignored; break;
            case ParseStatus::too_short: ++too_short; break;
            case ParseStatus::too_long: ++too_long; break;
            case ParseStatus::wrong_report_id: ++wrong_report_id; break;
            case ParseStatus::garbled: ++garbled; break;
        }
    }
};

// Little-endian field readers, bounds checked by the caller's length check.
inline std::uint16_t read_u16le(std::span<const std::uint8_t> r, std::size_t at) {
    return static_cast<std::uint16_t>(r[at] | (r[at + 1] << 8));
}
inline std::int16_t read_s16le(std::span<const std::uint8_t> r, std::size_t at) {
    return static_cast<std::int16_t>(read_u16le(r, at));
}
inline std::uint32_t read_u32le(std::span<const std::uint8_t> r, std::size_t at) {
    return static_cast<std::uint32_t>(r[at]) | (static_cast<std::uint32_t>(r[at + 1]) << 8) |
           (static_cast<std::uint32_t>(r[at + 2]) << 16) | (static_cast<std::uint32_t>(r[at + 3]) << 24);
}

// The PlayStation d-pad hat: 0 north, clockwise to 7 north-west, 8 released.
// Returns false for 9..15 (no such direction: a garbled report).
bool hat_to_dpad(std::uint8_t hat, std::uint32_t& buttons);

// Bluetooth reports of the Sony pads end in a CRC-32 (zlib polynomial) over a
// seed byte and the report.
std::uint32_t sony_bt_crc32(std::uint8_t seed, std::span<const std::uint8_t> data);

// USB vendor/product ids of the supported pads.
struct HidDeviceKind {
    std::uint16_t vendor_id;
    std::uint16_t product_id;
    HidFormat format;
    int interface_number;  // -1: any
    std::string_view name;
};
std::span<const HidDeviceKind> supported_hid_devices();
std::optional<HidDeviceKind> find_hid_device_kind(std::uint16_t vendor_id, std::uint16_t product_id, int interface_number);

}  // namespace marionette::input
