#pragma once
// HidTransport over hidapi's hidraw backend, and enumeration of supported pads.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "input/hid/hid_report.hpp"
#include "input/hid/hid_transport.hpp"

namespace marionette::input {

struct HidDeviceInfo {
    std::string path;  // /dev/hidrawN
    std::uint16_t vendor_id = 0, product_id = 0;
    int interface_number = -1;
    HidFormat format = HidFormat::ds4;
    std::string name;
};

// Supported pads present now (empty when hidapi cannot initialise or finds none).
std::vector<HidDeviceInfo> enumerate_hid_pads();

// Opens a device path non-blocking; null when it cannot be opened.
std::unique_ptr<HidTransport> open_hidapi_transport(const std::string& path);

}  // namespace marionette::input
