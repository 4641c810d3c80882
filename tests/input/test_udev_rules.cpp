// packaging/udev/70-marionette.rules against the ids the HID parsers accept
// (supported_hid_devices()): every pad has its USB and Bluetooth rule, and every
// rule grants the marionette group and the seat's user read access.
#include <catch2/catch.hpp>

#include <cstdio>
#include <sstream>

#include "input/hid/hid_report.hpp"
#include "tests/test_support.hpp"

using namespace marionette;

namespace {
std::string text(const char* format, unsigned a, unsigned b) {
    char buffer[128];
    std::snprintf(buffer, sizeof buffer, format, a, b);
    return buffer;
}
}  // namespace

TEST_CASE("udev rules name every supported pad and give the marionette group and the seat access", "[udev]") {
    const std::string rules = test::read_text_file(test::source_path("packaging/udev/70-marionette.rules"));
    for (const input::HidDeviceKind& d : input::supported_hid_devices()) {
        INFO(d.name);
        CHECK(rules.find(text("ATTRS{idVendor}==\"%04x\", ATTRS{idProduct}==\"%04x\"", d.vendor_id, d.product_id)) !=
              std::string::npos);
        CHECK(rules.find(text("KERNELS==\"*%04X:%04X*\"", d.vendor_id, d.product_id)) != std::string::npos);
    }
    CHECK(rules.find("ENV{ID_INPUT_JOYSTICK}==\"1\"") != std::string::npos);
    std::istringstream lines(rules);
    int rule_lines = 0;
    for (std::string line; std::getline(lines, line);) {
        if (line.empty() || line[0] == '#') continue;
        ++rule_lines;
        INFO(line);
        CHECK(line.find("GROUP=\"marionette\", MODE=\"0660\", TAG+=\"uaccess\"") != std::string::npos);
        CHECK((line.find("KERNEL==\"hidraw*|event*\"") == 0 || line.find("SUBSYSTEM==\"input\", KERNEL==\"event*\"") == 0));
    }
    CHECK(rule_lines == static_cast<int>(2 * input::supported_hid_devices().size() + 1));
}
