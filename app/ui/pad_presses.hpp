#pragma once
// What the tuning UI needs from the pad, found by the simulation thread tick by
// tick (app/live/pipeline.cpp): the buttons that went down in a tick, queued in
// order for the render thread, and the chord that opens and closes the UI
// (back + start held in the same tick).
#include <cstdint>

#include "runtime/handoff/spsc_ring.hpp"
#include "runtime/sim/tick_input.hpp"

namespace marionette::ui {

inline constexpr std::uint32_t kUiChord = button_bit(Button::back) | button_bit(Button::start);
// Bit 31 of a press event: the chord was made in that tick.
inline constexpr std::uint32_t kChordMade = 1u << 31;

// The buttons that went down in a tick (`previous`: the tick before's), plus
// kChordMade when back and start are both held now and were not before; 0: nothing.
inline std::uint32_t press_event(std::uint32_t previous, std::uint32_t now) {
    std::uint32_t event = now & ~previous;
    if ((now & kUiChord) == kUiChord && (previous & kUiChord) != kUiChord) event |= kChordMade;
    return event;
}

// Simulation → render thread, in tick order; a full queue drops the newest
// (256 presses: minutes of a person's input, seconds without a UI to read them).
using PadEventRing = SpscRing<std::uint32_t, 256>;

}  // namespace marionette::ui
