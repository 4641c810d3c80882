// The evdev pad's event state machine (input/evdev/evdev_state.hpp, what
// EvdevPad runs every libevdev event through). Input: one flags byte (bit 0:
// triggers on ABS_HAT2Y/X, bit 1: apply flat), then 8 axes x (min, max, flat,
// value) as little-endian int32, then events of 8 bytes (u16 type, u16 code,
// i32 value). EV_SYN/SYN_DROPPED stands for a resynchronisation, as EvdevPad
// handles it. Every frame's sample holds finite values in range.
#include <linux/input.h>

#include <cmath>
#include <cstring>

#include "input/evdev/evdev_state.hpp"
#include "tests/fuzz/fuzz_support.hpp"

using namespace marionette;
using namespace marionette::input;

namespace {
std::int32_t get_i32(const std::uint8_t* p) { return static_cast<std::int32_t>(fuzz::get_u32le(p)); }

void check(const InputSample& s) {
    const float axes[] = {s.lx, s.ly, s.rx, s.ry};
    for (float a : axes) fuzz::fuzz_check(std::isfinite(a) && a >= -1.0f && a <= 1.0f, "stick outside [-1, 1]");
    fuzz::fuzz_check(std::isfinite(s.lt) && s.lt >= 0.0f && s.lt <= 1.0f, "left trigger outside [0, 1]");
    fuzz::fuzz_check(std::isfinite(s.rt) && s.rt >= 0.0f && s.rt <= 1.0f, "right trigger outside [0, 1]");
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    constexpr std::size_t kConfig = 1 + EvdevState::kAxes * 16;
    if (size < kConfig) return 0;
    EvdevState state;
    if (data[0] & 1) {
        state.set_axis_code(EvdevState::kLt, ABS_HAT2Y);
        state.set_axis_code(EvdevState::kRt, ABS_HAT2X);
    }
    state.set_apply_flat((data[0] & 2) != 0);
    for (int i = 0; i < EvdevState::kAxes; ++i) {
        const std::uint8_t* a = data + 1 + 16 * i;
        state.set_axis_info(i, get_i32(a), get_i32(a + 4), 0, get_i32(a + 8), get_i32(a + 12));
    }
    InputSample sample;
    state.fill(sample);
    check(sample);
    for (std::size_t at = kConfig; at + 8 <= size; at += 8) {
        const std::uint16_t type = static_cast<std::uint16_t>(data[at] | (data[at + 1] << 8));
        const std::uint16_t code = static_cast<std::uint16_t>(data[at + 2] | (data[at + 3] << 8));
        const std::int32_t value = get_i32(data + at + 4);
        if (type == EV_SYN && code == SYN_DROPPED) {
            state.start_frame();
            state.fill(sample);
            check(sample);
        } else if (state.on_event(type, code, value)) {
            state.fill(sample);
            check(sample);
        }
    }
    return 0;
}
