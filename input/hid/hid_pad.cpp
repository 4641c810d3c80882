#include "input/hid/hid_pad.hpp"

#include "input/hid/ds4.hpp"
#include "input/hid/dualsense.hpp"
#include "input/hid/steam_deck.hpp"

namespace marionette::input {

ParseStatus parse_hid_report(HidFormat format, std::span<const std::uint8_t> report,
                             const switchpro::Calibration& cal, InputSample& out) {
    switch (format) {
        case HidFormat::ds4: return ds4::parse(report, out);
        case HidFormat::dualsense: return dualsense::parse(report, out);
        case HidFormat::switchpro: return switchpro::parse(report, cal, out);
        case HidFormat::steamdeck: return steamdeck::parse(report, out);
    }
    return ParseStatus::wrong_report_id;
}

bool HidPad::initialise(int timeout_ms) {
    if (format_ == HidFormat::steamdeck) {
        const auto clear = steamdeck::clear_digital_mappings_report();
        const auto settings = steamdeck::disable_lizard_settings_report();
        return transport_.send_feature(clear) >= 0 && transport_.send_feature(settings) >= 0;
    }
    if (format_ == HidFormat::switchpro) {
        // USB: handshake, then HID-only mode so the pad stops expecting a console.
        const std::uint8_t handshake[2] = {switchpro::kUsbCommand, switchpro::kUsbHandshake};
        const std::uint8_t force_hid[2] = {switchpro::kUsbCommand, switchpro::kUsbForceHid};
        if (transport_.write_report(handshake) < 0 || transport_.write_report(force_hid) < 0) return false;
        const std::uint8_t mode = switchpro::kFullReportId;
        const auto set_mode = switchpro::make_subcommand(subcommand_counter_++, switchpro::kSubcommandSetInputMode,
                                                         std::span<const std::uint8_t>(&mode, 1));
        if (transport_.write_report(set_mode) < 0) return false;
        read_switch_calibration(timeout_ms);
    }
    return true;
}

bool HidPad::read_switch_calibration(int timeout_ms) {
    const std::uint32_t a = switchpro::kFactoryStickCalAddress;
    const std::uint8_t args[5] = {static_cast<std::uint8_t>(a), static_cast<std::uint8_t>(a >> 8),
                                  static_cast<std::uint8_t>(a >> 16), static_cast<std::uint8_t>(a >> 24),
                                  static_cast<std::uint8_t>(switchpro::kFactoryStickCalSize)};
    const auto request = switchpro::make_subcommand(subcommand_counter_++, switchpro::kSubcommandSpiRead, args);
    if (transport_.write_report(request) < 0) return false;
    // Replies arrive among the input reports; give up after the timeout's worth of reads.
    for (int waited = 0; waited <= timeout_ms; ++waited) {
        const int n = transport_.read_report(buffer_, 1);
        if (n < 0) return false;
        if (n == 0) continue;
        const std::span<const std::uint8_t> r(buffer_.data(), static_cast<std::size_t>(n));
        if (r.size() < switchpro::kReplySpiData + switchpro::kFactoryStickCalSize) continue;
        if (r[0] != switchpro::kSubcommandReplyId || r[switchpro::kReplySubcommand] != switchpro::kSubcommandSpiRead) continue;
        if (read_u32le(r, switchpro::kReplySpiAddress) != a) continue;
        return switchpro::decode_factory_calibration(r.subspan(switchpro::kReplySpiData, switchpro::kFactoryStickCalSize),
                                                     switch_cal_);
    }
    return false;
}

HidPad::Result HidPad::read(InputSample& out, int timeout_ms) {
    const int n = transport_.read_report(buffer_, timeout_ms);
    if (n < 0) return Result::disconnected;
    if (n == 0) return Result::nothing;
    last_size_ = static_cast<std::size_t>(n);
    last_status_ = parse_hid_report(format_, std::span<const std::uint8_t>(buffer_.data(), last_size_), switch_cal_, out);
    counters_.count(last_status_);
    if (format_ == HidFormat::steamdeck && ++reports_since_watchdog_ >= steamdeck::kWatchdogReports) {
        // The firmware re-enables lizard mode unless told again.
        reports_since_watchdog_ = 0;
        const auto settings = steamdeck::disable_lizard_settings_report();
        transport_.send_feature(settings);
    }
    if (last_status_ == ParseStatus::ok) return Result::sample;
    return last_status_ == ParseStatus::ignored ? Result::nothing : Result::rejected;
}

}  // namespace marionette::input
