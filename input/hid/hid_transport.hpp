#pragma once
// How a HID pad is reached: hidapi's hidraw backend for real devices
// (hidapi_transport.hpp), firmware_sim's in-process device for tests. The
// parsers and HidPad see only this.
#include <cstdint>
#include <span>

namespace marionette::input {

class HidTransport {
public:
    virtual ~HidTransport() = default;
    // One input report, exactly as hidraw's read() returns it (report id first
    // where the device uses one). Returns its length, 0 when none arrived within
    // timeout_ms (0: do not wait), -1 when the device is gone or failed.
    virtual int read_report(std::span<std::uint8_t> buffer, int timeout_ms) = 0;
    // Output report (report id first). Returns bytes written or -1.
    virtual int write_report(std::span<const std::uint8_t> report) = 0;
    // Feature reports (report id first; 0 for devices without ids). Return bytes or -1.
    virtual int send_feature(std::span<const std::uint8_t> report) = 0;
    virtual int get_feature(std::span<std::uint8_t> buffer) = 0;
};

}  // namespace marionette::input
