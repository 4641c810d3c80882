#include "app/ui/pad_presses.hpp"

namespace marionette::ui {

namespace {
constexpr std::array<Button, 4> kDirectionButtons = {Button::dpad_up, Button::dpad_down, Button::dpad_left,
                                                     Button::dpad_right};
}  // namespace

std::uint32_t PadStepper::frame(PadPress press, std::uint32_t held, std::uint64_t held_tick, std::int64_t tick_ns,
                                bool caught_up) {
    if (shown_ != 0) {  // the release frame between two steps
        shown_ = 0;
        return 0;
    }
    std::uint32_t out = press.event & kStepButtons;
    for (std::size_t i = 0; i < kDirectionButtons.size(); ++i) {
        const std::uint32_t bit = button_bit(kDirectionButtons[i]);
        if (press.event & bit) {  // a press edge: one step now, the repeat clock starts at its tick
            tracked_[i] = true;
            down_tick_[i] = press.tick;
            repeats_[i] = 0;
            continue;
        }
        if (!tracked_[i] || !caught_up) continue;  // a queued press may still be ahead of `held`
        if ((held & bit) == 0) {
            tracked_[i] = false;  // released: no repeat until the next press edge
            continue;
        }
        if (out != 0 || held_tick < down_tick_[i]) continue;  // one step per frame
        const std::int64_t hold_ns = static_cast<std::int64_t>(held_tick - down_tick_[i]) * tick_ns;
        const std::int64_t due = hold_ns < kRepeatDelayNs ? 0 : 1 + (hold_ns - kRepeatDelayNs) / kRepeatIntervalNs;
        if (repeats_[i] < due) {
            ++repeats_[i];
            out |= bit;
        }
    }
    shown_ = out;
    return out;
}

}  // namespace marionette::ui
