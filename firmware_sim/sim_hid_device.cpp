#include "firmware_sim/sim_hid_device.hpp"

#include <algorithm>

#include "input/hid/steam_deck.hpp"

namespace marionette::firmware_sim {

using namespace marionette::input;

SimHidDevice::SimHidDevice(SimStream stream, HidFormat format, switchpro::Calibration calibration,
                           bool calibration_readable)
    : stream_(std::move(stream)), format_(format), calibration_(calibration), calibration_readable_(calibration_readable) {}

int SimHidDevice::read_report(std::span<std::uint8_t> buffer, int /*timeout_ms*/) {
    if (unplugged_) return -1;
    if (!replies_.empty()) {
        const Report r = replies_.front();
        replies_.pop_front();
        const std::size_t n = std::min(buffer.size(), r.size);
        std::copy_n(r.bytes.begin(), n, buffer.begin());
        return static_cast<int>(n);
    }
    while (next_ < stream_.frames.size()) {
        const SimFrame& f = stream_.frames[next_++];
        if (f.kind == SimFrame::Kind::unplug) {
            unplugged_ = true;
            return -1;
        }
        if (f.kind != SimFrame::Kind::report) continue;
        // hidraw truncates a report to the reader's buffer; so do we.
        const std::size_t n = std::min(buffer.size(), f.report.size);
        std::copy_n(f.report.bytes.begin(), n, buffer.begin());
        return static_cast<int>(n);
    }
    return 0;  // nothing more: a pad at rest sends nothing new
}

bool SimHidDevice::replug() {
    if (!unplugged_) return false;
    while (next_ < stream_.frames.size() && stream_.frames[next_].kind != SimFrame::Kind::replug) ++next_;
    if (next_ < stream_.frames.size()) ++next_;
    unplugged_ = false;
    return true;
}

int SimHidDevice::write_report(std::span<const std::uint8_t> r) {
    if (unplugged_) return -1;
    if (format_ != HidFormat::switchpro || r.empty()) return static_cast<int>(r.size());
    if (r[0] == switchpro::kUsbCommand && r.size() >= 2) {
        Report ack;  // USB command acknowledgements (0x81 xx) are ignored by the parser
        ack.size = switchpro::kUsbReportSize;
        ack.bytes[0] = switchpro::kUsbReplyId;
        ack.bytes[1] = r[1];
        replies_.push_back(ack);
        return static_cast<int>(r.size());
    }
    if (r[0] != switchpro::kOutputSubcommand || r.size() < 16) return static_cast<int>(r.size());
    Report reply;
    reply.size = switchpro::kUsbReportSize;
    reply.bytes[0] = switchpro::kSubcommandReplyId;
    reply.bytes[13] = 0x80;  // ack
    reply.bytes[switchpro::kReplySubcommand] = r[10];
    if (r[10] == switchpro::kSubcommandSpiRead) {
        ++spi_reads_;
        reply.bytes[13] = 0x90;  // ack with data
        std::copy_n(r.begin() + 11, 5, reply.bytes.begin() + switchpro::kReplySpiAddress);
        const std::uint32_t address = read_u32le(r, 11);
        const std::size_t size = std::min<std::size_t>(r[15], reply.size - switchpro::kReplySpiData);
        if (address == switchpro::kFactoryStickCalAddress) {
            const auto block = calibration_readable_ ? encode_factory_calibration(calibration_)
                                                     : std::array<std::uint8_t, switchpro::kFactoryStickCalSize>{
                                                           0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF,
                                                           0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
            std::copy_n(block.begin(), std::min(size, block.size()), reply.bytes.begin() + switchpro::kReplySpiData);
        }
    }
    replies_.push_back(reply);
    return static_cast<int>(r.size());
}

int SimHidDevice::send_feature(std::span<const std::uint8_t> r) {
    if (unplugged_) return -1;
    if (format_ == HidFormat::steamdeck && r.size() >= 3) {
        if (r[1] == steamdeck::kClearDigitalMappings) mappings_cleared_ = true;
        if (r[1] == steamdeck::kSetSettingsValues) {
            // Lizard mode is off once the digital mappings are cleared and both
            // trackpads are set to "none".
            bool left_none = false, right_none = false;
            for (std::size_t at = 3; at + 2 < r.size() && at < 3u + r[2]; at += 3) {
                const std::uint16_t value = static_cast<std::uint16_t>(r[at + 1] | (r[at + 2] << 8));
                if (r[at] == steamdeck::kSettingLeftTrackpadMode) left_none = value == steamdeck::kTrackpadNone;
                if (r[at] == steamdeck::kSettingRightTrackpadMode) right_none = value == steamdeck::kTrackpadNone;
            }
            ++lizard_settings_;
            if (mappings_cleared_ && left_none && right_none) lizard_mode_ = false;
        }
    }
    return static_cast<int>(r.size());
}

int SimHidDevice::get_feature(std::span<std::uint8_t> buffer) {
    if (unplugged_) return -1;
    std::fill(buffer.begin(), buffer.end(), std::uint8_t{0});
    return static_cast<int>(buffer.size());
}

}  // namespace marionette::firmware_sim
