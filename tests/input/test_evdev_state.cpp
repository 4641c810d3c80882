// EvdevState: the evdev pad's per-event state machine (input/evdev/evdev_state.hpp),
// which EvdevPad runs every libevdev event through and tests/fuzz/fuzz_evdev drives.
#include <catch2/catch.hpp>

#include <linux/input.h>

#include "input/evdev/evdev_state.hpp"

using namespace marionette;
using namespace marionette::input;

namespace {
EvdevState xbox_like() {
    EvdevState s;
    for (int i = EvdevState::kLx; i <= EvdevState::kRy; ++i) s.set_axis_info(i, -32768, 32767, 16, 128, 0);
    s.set_axis_info(EvdevState::kLt, 0, 1023, 0, 0, 0);
    s.set_axis_info(EvdevState::kRt, 0, 1023, 0, 0, 0);
    s.set_axis_info(EvdevState::kHatX, -1, 1, 0, 0, 0);
    s.set_axis_info(EvdevState::kHatY, -1, 1, 0, 0, 0);
    return s;
}
}  // namespace

TEST_CASE("evdev state: a frame ends at a SYN_REPORT after events, never at an empty one") {
    EvdevState s = xbox_like();
    CHECK_FALSE(s.on_event(EV_SYN, SYN_REPORT, 0));  // empty: the tail of a dropped packet
    CHECK_FALSE(s.on_event(EV_ABS, ABS_X, 32767));
    CHECK_FALSE(s.on_event(EV_SYN, SYN_MT_REPORT, 0));
    CHECK(s.on_event(EV_SYN, SYN_REPORT, 0));
    CHECK_FALSE(s.on_event(EV_SYN, SYN_REPORT, 0));
    InputSample out;
    s.fill(out);
    CHECK(out.lx == 1.0f);
    CHECK(out.ly == 0.0f);
}

TEST_CASE("evdev state: axes, flat zone, y flipped, hat as d-pad, buttons by position") {
    EvdevState s = xbox_like();
    s.on_event(EV_ABS, ABS_Y, -32768);  // evdev y grows downwards: full up
    s.on_event(EV_ABS, ABS_RX, 100);    // inside the flat zone (128)
    s.on_event(EV_ABS, ABS_Z, 1023);
    s.on_event(EV_ABS, ABS_HAT0X, -1);
    s.on_event(EV_ABS, ABS_HAT0Y, 1);
    s.on_event(EV_KEY, BTN_SOUTH, 1);
    s.on_event(EV_KEY, BTN_START, 1);
    s.on_event(EV_KEY, KEY_A, 1);  // not a pad button: ignored
    REQUIRE(s.on_event(EV_SYN, SYN_REPORT, 0));
    InputSample out;
    s.fill(out);
    CHECK(out.ly == 1.0f);
    CHECK(out.rx == 0.0f);
    CHECK(out.lt == 1.0f);
    CHECK(out.rt == 0.0f);
    CHECK(out.buttons == (button_bit(Button::south) | button_bit(Button::start) | button_bit(Button::dpad_left) |
                          button_bit(Button::dpad_down)));
    s.set_apply_flat(false);
    s.fill(out);
    CHECK(out.rx > 0.0f);
    s.on_event(EV_KEY, BTN_SOUTH, 0);
    s.on_event(EV_SYN, SYN_REPORT, 0);
    s.fill(out);
    CHECK((out.buttons & button_bit(Button::south)) == 0);
}

TEST_CASE("evdev state: digital triggers only without analog ones, and triggers from ABS_HAT2Y or ABS_HAT2X") {
    EvdevState digital;
    digital.set_axis_info(EvdevState::kLx, 0, 255, 0, 0, 128);
    digital.on_event(EV_KEY, BTN_TL2, 1);
    digital.on_event(EV_KEY, BTN_TR2, 1);
    InputSample out;
    digital.fill(out);
    CHECK(out.lt == 1.0f);
    CHECK(out.rt == 1.0f);

    EvdevState hat2;
    hat2.set_axis_code(EvdevState::kLt, ABS_HAT2Y);
    hat2.set_axis_info(EvdevState::kLt, 0, 255, 0, 0, 0);
    hat2.on_event(EV_ABS, ABS_HAT2Y, 51);
    hat2.on_event(EV_ABS, ABS_Z, 255);  // not this pad's trigger axis
    hat2.on_event(EV_KEY, BTN_TL2, 1);  // the analog trigger wins
    hat2.fill(out);
    CHECK(out.lt == Approx(0.2f));
}

TEST_CASE("evdev state: an axis whose range is empty is absent and reads 0") {
    EvdevState s;
    s.set_axis_info(EvdevState::kLx, 5, 5, 0, 0, 5);
    CHECK_FALSE(s.abs(EvdevState::kLx).present);
    s.on_event(EV_ABS, ABS_X, 1000);
    InputSample out;
    s.fill(out);
    CHECK(out.lx == 0.0f);
}
