#include "input/evdev/evdev_state.hpp"

#include <linux/input.h>

namespace marionette::input {

namespace {
struct KeyMap {
    std::uint16_t code;
    Button button;
};
// gamepad.rst: BTN_SOUTH/EAST/NORTH/WEST are positions, whatever the labels.
constexpr KeyMap kKeys[] = {
    {BTN_SOUTH, Button::south},          {BTN_EAST, Button::east},
    {BTN_WEST, Button::west},            {BTN_NORTH, Button::north},
    {BTN_TL, Button::left_shoulder},     {BTN_TR, Button::right_shoulder},
    {BTN_SELECT, Button::back},          {BTN_START, Button::start},
    {BTN_MODE, Button::guide},           {BTN_THUMBL, Button::left_stick},
    {BTN_THUMBR, Button::right_stick},   {BTN_DPAD_UP, Button::dpad_up},
    {BTN_DPAD_DOWN, Button::dpad_down},  {BTN_DPAD_LEFT, Button::dpad_left},
    {BTN_DPAD_RIGHT, Button::dpad_right},
};
constexpr int kKeyCount = sizeof(kKeys) / sizeof(kKeys[0]);
// Digital triggers, after the mapped buttons.
constexpr int kKeyTl2 = kKeyCount, kKeyTr2 = kKeyCount + 1;
}  // namespace

EvdevState::EvdevState() {
    const std::uint16_t codes[kAxes] = {ABS_X, ABS_Y, ABS_RX, ABS_RY, ABS_Z, ABS_RZ, ABS_HAT0X, ABS_HAT0Y};
    for (int i = 0; i < kAxes; ++i) abs_code_[i] = codes[i];
}

void EvdevState::set_axis_info(int i, std::int32_t min, std::int32_t max, std::int32_t fuzz, std::int32_t flat,
                               std::int32_t value) {
    abs_value_[i] = value;
    abs_[i] = max > min ? EvdevAbs{true, min, max, fuzz, flat} : EvdevAbs{};
}

int EvdevState::key_index(std::uint16_t code) {
    for (int k = 0; k < kKeyCount; ++k)
        if (kKeys[k].code == code) return k;
    if (code == BTN_TL2) return kKeyTl2;
    if (code == BTN_TR2) return kKeyTr2;
    return -1;
}

void EvdevState::set_key(std::uint16_t code, bool pressed) {
    const int k = key_index(code);
    if (k < 0) return;
    if (pressed) keys_ |= 1u << k;
    else keys_ &= ~(1u << k);
}

bool EvdevState::on_event(std::uint16_t type, std::uint16_t code, std::int32_t value) {
    if (type == EV_SYN) {
        if (code != SYN_REPORT || events_in_frame_ == 0) return false;
        events_in_frame_ = 0;
        return true;
    }
    ++events_in_frame_;
    if (type == EV_ABS) {
        // The hat axes are read as ABS_HAT0X/Y whatever the trigger codes are,
        // so every axis with this code takes the value.
        for (int i = 0; i < kAxes; ++i)
            if (abs_code_[i] == code) abs_value_[i] = value;
    } else if (type == EV_KEY) {
        set_key(code, value != 0);
    }
    return false;
}

float EvdevState::axis_value(int i, bool centred) const {
    const EvdevAbs& a = abs_[i];
    if (!a.present) return 0.0f;
    const std::int32_t v = abs_value_[i];
    if (!centred) return normalise_trigger(v, a.min, a.max);
    if (apply_flat_ && a.flat > 0) {
        const std::int64_t centre = static_cast<std::int64_t>(a.min) + (static_cast<std::int64_t>(a.max) - a.min + 1) / 2;
        if (v - centre <= a.flat && centre - v <= a.flat) return 0.0f;
    }
    return normalise_centred(v, a.min, a.max);
}

void EvdevState::fill(InputSample& s) const {
    s.lx = axis_value(kLx, true);
    s.ly = flip_axis(axis_value(kLy, true));  // evdev y grows downwards
    s.rx = axis_value(kRx, true);
    s.ry = flip_axis(axis_value(kRy, true));
    s.lt = axis_value(kLt, false);
    s.rt = axis_value(kRt, false);
    std::uint32_t b = 0;
    for (int k = 0; k < kKeyCount; ++k)
        if (keys_ & (1u << k)) b |= button_bit(kKeys[k].button);
    if (abs_[kHatX].present) {
        const std::int32_t x = abs_value_[kHatX];
        if (x < 0) b |= button_bit(Button::dpad_left);
        if (x > 0) b |= button_bit(Button::dpad_right);
    }
    if (abs_[kHatY].present) {
        const std::int32_t y = abs_value_[kHatY];
        if (y < 0) b |= button_bit(Button::dpad_up);
        if (y > 0) b |= button_bit(Button::dpad_down);
    }
    if (!abs_[kLt].present && (keys_ & (1u << kKeyTl2))) s.lt = 1.0f;
    if (!abs_[kRt].present && (keys_ & (1u << kKeyTr2))) s.rt = 1.0f;
    s.buttons = b;
    s.has_device_counter = false;
}

}  // namespace marionette::input
