#include "input/hid/hidapi_transport.hpp"

#include <hidapi/hidapi.h>

namespace marionette::input {

namespace {

class HidapiTransport final : public HidTransport {
public:
    explicit HidapiTransport(hid_device* device) : device_(device) {}
    ~HidapiTransport() override { hid_close(device_); }
    int read_report(std::span<std::uint8_t> buffer, int timeout_ms) override {
        return hid_read_timeout(device_, buffer.data(), buffer.size(), timeout_ms);
    }
    int write_report(std::span<const std::uint8_t> report) override {
        return hid_write(device_, report.data(), report.size());
    }
    int send_feature(std::span<const std::uint8_t> report) override {
        return hid_send_feature_report(device_, report.data(), report.size());
    }
    int get_feature(std::span<std::uint8_t> buffer) override {
        return hid_get_feature_report(device_, buffer.data(), buffer.size());
    }

private:
    hid_device* device_;
};

std::string narrow(const wchar_t* w) {
    std::string out;
    if (!w) return out;
    for (; *w; ++w) out += (*w < 128) ? static_cast<char>(*w) : '?';
    return out;
}

}  // namespace

std::vector<HidDeviceInfo> enumerate_hid_pads() {
    std::vector<HidDeviceInfo> out;
    if (hid_init() != 0) return out;
    hid_device_info* list = hid_enumerate(0, 0);
    for (hid_device_info* d = list; d; d = d->next) {
        const auto kind = find_hid_device_kind(d->vendor_id, d->product_id, d->interface_number);
        if (!kind) continue;
        HidDeviceInfo info;
        info.path = d->path ? d->path : "";
        info.vendor_id = d->vendor_id;
        info.product_id = d->product_id;
        info.interface_number = d->interface_number;
        info.format = kind->format;
        info.name = narrow(d->product_string);
        if (info.name.empty()) info.name = std::string(kind->name);
        out.push_back(std::move(info));
    }
    hid_free_enumeration(list);
    return out;
}

std::unique_ptr<HidTransport> open_hidapi_transport(const std::string& path) {
    if (hid_init() != 0) return nullptr;
    hid_device* device = hid_open_path(path.c_str());
    if (!device) return nullptr;
    hid_set_nonblocking(device, 0);
    return std::make_unique<HidapiTransport>(device);
}

}  // namespace marionette::input
