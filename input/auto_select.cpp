#include "input/auto_select.hpp"

#include <cstdio>

#include "input/hid/hid_report.hpp"

namespace marionette::input {

namespace {
std::string ids(std::uint16_t v, std::uint16_t p) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "%04x:%04x", v, p);
    return buf;
}
}  // namespace

std::string_view backend_name(BackendKind k) {
    switch (k) {
        case BackendKind::hidraw: return "hidraw";
        case BackendKind::evdev: return "evdev";
        case BackendKind::sdl: return "sdl";
        case BackendKind::none: return "none";
    }
    return "none";
}

std::optional<BackendKind> backend_from_name(std::string_view name) {
    if (name == "hidraw" || name == "hid") return BackendKind::hidraw;
    if (name == "evdev") return BackendKind::evdev;
    if (name == "sdl" || name == "sdl2") return BackendKind::sdl;
    return std::nullopt;
}

BackendChoice choose_input_backend(const AutoSelectInputs& found) {
    int unreadable = 0;
    for (const HidCandidate& h : found.hid) {
        const auto kind = find_hid_device_kind(h.vendor_id, h.product_id, h.interface_number);
        if (!kind) continue;
        if (!h.openable) {
            ++unreadable;
            continue;
        }
        return {BackendKind::hidraw, "hidraw: " + std::string(kind->name) + " " + ids(h.vendor_id, h.product_id)};
    }
    const std::string note = unreadable ? " (a supported pad's hidraw node is not readable; see docs/input.md for the udev rule)" : "";
    if (!found.evdev.empty()) {
        const EvdevCandidate& e = found.evdev.front();
        return {BackendKind::evdev, "evdev: " + e.path + " " + ids(e.vendor_id, e.product_id) + note};
    }
    // SDL2 initialising says nothing about a pad: with zero joysticks it would
    // open nothing and the run would sit idle, so "none" (the caller falls back).
    if (found.sdl_available && found.sdl_joysticks > 0)
        return {BackendKind::sdl, "sdl: no hidraw or evdev gamepad; SDL2 sees " + std::to_string(found.sdl_joysticks) +
                                      " joystick(s)" + note};
    return {BackendKind::none, "no gamepad found by hidraw, evdev or SDL2" + note};
}

}  // namespace marionette::input
