#pragma once
// The evdev pad's per-event state machine, with no file descriptor and no
// libevdev: the values of the axes and buttons a gamepad has, updated one
// (type, code, value) event at a time, frame boundaries (SYN_REPORT), and the
// sample a frame stands for. EvdevPad feeds it every event libevdev delivers
// (sync events after SYN_DROPPED too); tests/fuzz/fuzz_evdev.cpp feeds it
// arbitrary events.
#include <cstdint>

#include "input/input_sample.hpp"

namespace marionette::input {

struct EvdevAbs {
    bool present = false;
    std::int32_t min = 0, max = 0, fuzz = 0, flat = 0;
};

class EvdevState {
public:
    // lx ly rx ry lt rt hatx haty
    static constexpr int kAxes = 8;
    enum AxisIndex { kLx, kLy, kRx, kRy, kLt, kRt, kHatX, kHatY };

    // The axes read by default (ABS_X ABS_Y ABS_RX ABS_RY ABS_Z ABS_RZ ABS_HAT0X ABS_HAT0Y).
    EvdevState();

    // The evdev code axis `index` is read from (the triggers may come from
    // ABS_HAT2Y/ABS_HAT2X instead of ABS_Z/ABS_RZ).
    void set_axis_code(int index, std::uint16_t code) { abs_code_[index] = code; }
    std::uint16_t axis_code(int index) const { return abs_code_[index]; }
    // The axis's range from the device's absinfo and its current value; the
    // axis is present only when max > min. The analog triggers follow presence.
    void set_axis_info(int index, std::int32_t min, std::int32_t max, std::int32_t fuzz, std::int32_t flat,
                       std::int32_t value);
    const EvdevAbs& abs(int index) const { return abs_[index]; }
    // A button's state before the first event (EVIOCGKEY).
    void set_key(std::uint16_t code, bool pressed);
    void set_apply_flat(bool apply) { apply_flat_ = apply; }

    // One event. True when it completes a frame: a SYN_REPORT after at least one
    // non-SYN event (the kernel never sends an empty frame; one here ends a
    // packet lost to SYN_DROPPED, and skipping it makes the result independent
    // of when the drain happened).
    bool on_event(std::uint16_t type, std::uint16_t code, std::int32_t value);
    // After a SYN_DROPPED resynchronisation: the state is complete again.
    void start_frame() { events_in_frame_ = 0; }

    // The sample the current state stands for (everything but the time stamp).
    void fill(InputSample& out) const;

private:
    float axis_value(int index, bool centred) const;
    static int key_index(std::uint16_t code);  // -1: not a key the pad reads

    EvdevAbs abs_[kAxes];
    std::uint16_t abs_code_[kAxes] = {};
    std::int32_t abs_value_[kAxes] = {};
    std::uint32_t keys_ = 0;  // bit key_index(code)
    bool apply_flat_ = true;
    int events_in_frame_ = 0;
};

}  // namespace marionette::input
