#pragma once
// firmware_sim as a HID device in the same process: it implements the
// HidTransport interface hidapi implements, so HidPad and the parsers run
// exactly as with a real pad. It answers the Switch Pro's SPI-read subcommand
// with its factory calibration and honours the Steam Deck's lizard-mode feature
// reports. Reads play the stream in order, ignoring time (tests run as fast as
// they can); an unplug frame makes reads fail until replug().
#include <cstdint>
#include <deque>

#include "firmware_sim/sim_pad.hpp"
#include "input/hid/hid_transport.hpp"

namespace marionette::firmware_sim {

class SimHidDevice final : public input::HidTransport {
public:
    SimHidDevice(SimStream stream, input::HidFormat format,
                 input::switchpro::Calibration calibration = kSimSwitchCalibration, bool calibration_readable = true);

    int read_report(std::span<std::uint8_t> buffer, int timeout_ms) override;
    int write_report(std::span<const std::uint8_t> report) override;
    int send_feature(std::span<const std::uint8_t> report) override;
    int get_feature(std::span<std::uint8_t> buffer) override;

    bool unplugged() const { return unplugged_; }
    bool finished() const { return next_ >= stream_.frames.size() && replies_.empty(); }
    // After an unplug frame: the pad is back (true), or there was no unplug (false).
    bool replug();
    bool lizard_mode() const { return lizard_mode_; }
    int lizard_settings_received() const { return lizard_settings_; }
    int spi_reads() const { return spi_reads_; }

private:
    SimStream stream_;
    input::HidFormat format_;
    input::switchpro::Calibration calibration_;
    bool calibration_readable_;
    std::size_t next_ = 0;
    bool unplugged_ = false;
    bool lizard_mode_ = true;
    bool mappings_cleared_ = false;
    int lizard_settings_ = 0;
    int spi_reads_ = 0;
    std::deque<Report> replies_;  // subcommand replies, sent before the next input report
};

}  // namespace marionette::firmware_sim
