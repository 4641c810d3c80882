#pragma once
// Drives the tuning UI as the render thread does in the headless UI tests: one
// frame per tick of pad input, the press events derived from the held buttons
// (ui::press_event), each frame drawn over a fixed state and overlay.
#include <cstdint>

#include "app/ui/pad_presses.hpp"
#include "app/ui/tuning_ui.hpp"
#include "render_es/overlay.hpp"
#include "render_es/view.hpp"
#include "runtime/sim/simulation.hpp"

namespace marionette::test {

class UiPadDriver {
public:
    UiPadDriver(ui::TuningUi& tuning, render::View& view, const PuppetState& state, const render::DebugOverlay& overlay)
        : tuning_(tuning), view_(view), state_(state), overlay_(overlay) {}

    // One tick of pad input with `buttons` held, then one frame.
    void frame(std::uint32_t buttons) {
        const std::uint32_t event = ui::press_event(held_, buttons);
        held_ = buttons;
        TickInput pad;
        pad.buttons = buttons;
        ++tick_;
        tuning_.feed_pad(pad, tick_, 8'333'333, ui::PadPress{event, tick_}, true);
        view_.frame(state_, overlay_, "", 1.0f / 60.0f);
    }

    // Press and release one button (two frames).
    void press(Button b) {
        frame(button_bit(b));
        frame(0);
    }

private:
    ui::TuningUi& tuning_;
    render::View& view_;
    const PuppetState& state_;
    const render::DebugOverlay& overlay_;
    std::uint32_t held_ = 0;
    std::uint64_t tick_ = 0;
};

}  // namespace marionette::test
