// `--input auto`: hidraw for supported pads, evdev for other gamepads, SDL2 when
// neither is available.
#include <catch2/catch.hpp>

#include "input/auto_select.hpp"

using namespace marionette::input;

TEST_CASE("auto: a supported HID pad wins over evdev", "[input][auto]") {
    AutoSelectInputs in;
    in.hid.push_back({0x046d, 0xc52b, 0, true});  // a receiver: not a pad
    in.hid.push_back({0x054c, 0x0ce6, 3, true});
    in.evdev.push_back({"/dev/input/event5", 0x054c, 0x0ce6});
    in.sdl_available = true;
    const BackendChoice c = choose_input_backend(in);
    CHECK(c.kind == BackendKind::hidraw);
    CHECK(c.reason == "hidraw: Sony DualSense 054c:0ce6");
}

TEST_CASE("auto: an unsupported or unreadable HID pad falls back to evdev", "[input][auto]") {
    AutoSelectInputs in;
    in.hid.push_back({0x28de, 0x1205, 2, false});  // Deck, hidraw not readable
    in.evdev.push_back({"/dev/input/event7", 0x045e, 0x028e});
    BackendChoice c = choose_input_backend(in);
    CHECK(c.kind == BackendKind::evdev);
    CHECK_THAT(c.reason, Catch::StartsWith("evdev: /dev/input/event7 045e:028e"));
    CHECK_THAT(c.reason, Catch::Contains("not readable"));
    in.hid.clear();
    in.hid.push_back({0x28de, 0x1205, 0, true});  // the Deck's mouse interface is not the pad
    CHECK(choose_input_backend(in).kind == BackendKind::evdev);
}

TEST_CASE("auto: SDL2 when neither hidraw nor evdev has a pad, none when SDL2 is missing too", "[input][auto]") {
    AutoSelectInputs in;
    in.sdl_available = true;
    in.sdl_joysticks = 1;
    CHECK(choose_input_backend(in).kind == BackendKind::sdl);
    in.sdl_joysticks = 0;  // SDL2 works but sees no pad: nothing to open
    CHECK(choose_input_backend(in).kind == BackendKind::none);
    in.sdl_available = false;
    const BackendChoice c = choose_input_backend(in);
    CHECK(c.kind == BackendKind::none);
    CHECK(c.reason == "no gamepad found by hidraw, evdev or SDL2");
}

TEST_CASE("backend names parse both ways", "[input][auto]") {
    for (BackendKind k : {BackendKind::hidraw, BackendKind::evdev, BackendKind::sdl})
        CHECK(backend_from_name(backend_name(k)) == k);
    CHECK(backend_from_name("hid") == BackendKind::hidraw);
    CHECK_FALSE(backend_from_name("usb"));
}
