#pragma once
// `--input auto`: which backend reads the pads, as a pure function of what was
// found, so the rule is tested without devices. hidraw for supported pads
// (byte-exact parsers, device counters, no kernel remapping), evdev for any
// other gamepad, SDL2 when neither is available.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace marionette::input {

enum class BackendKind : std::uint8_t { hidraw, evdev, sdl, none };
std::string_view backend_name(BackendKind kind);
std::optional<BackendKind> backend_from_name(std::string_view name);  // hidraw|hid, evdev, sdl

struct HidCandidate {
    std::uint16_t vendor_id = 0, product_id = 0;
    int interface_number = -1;
    bool openable = true;   // hidraw node readable by us
};
struct EvdevCandidate {
    std::string path;
    std::uint16_t vendor_id = 0, product_id = 0;
};
struct AutoSelectInputs {
    std::vector<HidCandidate> hid;      // every hidraw device seen
    std::vector<EvdevCandidate> evdev;  // evdev nodes that are gamepads
    bool sdl_available = false;         // SDL2's joystick subsystem initialised
    int sdl_joysticks = 0;
};
struct BackendChoice {
    BackendKind kind = BackendKind::none;
    std::string reason;  // one sentence for the user ("hidraw: Sony DualSense 054c:0ce6")
};

BackendChoice choose_input_backend(const AutoSelectInputs& found);

}  // namespace marionette::input
