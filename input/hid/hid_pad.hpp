#pragma once
// One HID pad: a transport, the format's parser, its start-up dialogue (Steam
// Deck: lizard mode off and the watchdog; Switch Pro: USB handshake and the
// factory stick calibration from SPI flash) and the counters of rejected
// reports. read() never allocates.
#include <array>
#include <cstdint>

#include "input/hid/hid_report.hpp"
#include "input/hid/hid_transport.hpp"
#include "input/hid/switch_pro.hpp"

namespace marionette::input {

// Stateless dispatch to the family parsers.
ParseStatus parse_hid_report(HidFormat format, std::span<const std::uint8_t> report,
                             const switchpro::Calibration& switch_calibration, InputSample& out);

class HidPad {
public:
    HidPad(HidTransport& transport, HidFormat format) : transport_(transport), format_(format) {}

    // Start-up dialogue; waits at most timeout_ms for replies. Returns false only
    // when the device failed; a Switch Pro whose calibration cannot be read keeps
    // the defaults (calibration().from_device says which).
    bool initialise(int timeout_ms);

    enum class Result : std::uint8_t { sample, nothing, rejected, disconnected };
    // One report within timeout_ms (0: only what is already there).
    Result read(InputSample& out, int timeout_ms);

    HidFormat format() const { return format_; }
    const ParseCounters& counters() const { return counters_; }
    const switchpro::Calibration& calibration() const { return switch_cal_; }
    ParseStatus last_status() const { return last_status_; }
    // The bytes of the last report read (for --raw dumps).
    std::span<const std::uint8_t> last_report() const { return {buffer_.data(), last_size_}; }

private:
    bool read_switch_calibration(int timeout_ms);
    HidTransport& transport_;
    HidFormat format_;
    switchpro::Calibration switch_cal_ = switchpro::kDefaultCalibration;
    ParseCounters counters_;
    ParseStatus last_status_ = ParseStatus::ok;
    std::array<std::uint8_t, 128> buffer_{};
    std::size_t last_size_ = 0;
    int reports_since_watchdog_ = 0;
    std::uint8_t subcommand_counter_ = 0;
};

}  // namespace marionette::input
