#pragma once
// What the tuning UI needs from the pad, found by the simulation thread tick by
// tick (app/live/pipeline.cpp): the buttons that went down in a tick, stamped
// with that tick and queued in order for the render thread, and the chord that
// opens and closes the UI (back + start held in the same tick).
//
// The UI takes presses as discrete events (PadStepper): a press edge is exactly
// one navigation or activation step whatever the frame times are, and a d-pad
// direction repeats only while it is held for kRepeatDelayNs of simulation
// time, counted from its press edge's tick (never from summed frame times).
#include <array>
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

// One press event and the simulation tick it happened in (the tick count after
// that tick, as in PuppetState::tick).
struct PadPress {
    std::uint32_t event = 0;  // press_event(); 0: none
    std::uint64_t tick = 0;
};

// Simulation → render thread, in tick order; a full queue drops the newest
// (256 presses: minutes of a person's input, seconds without a UI to read them).
using PadEventRing = SpscRing<PadPress, 256>;

// The buttons ImGui navigation sees as steps, and the ones that repeat when held.
inline constexpr std::uint32_t kDpadButtons = button_bit(Button::dpad_up) | button_bit(Button::dpad_down) |
                                              button_bit(Button::dpad_left) | button_bit(Button::dpad_right);
inline constexpr std::uint32_t kStepButtons = kDpadButtons | button_bit(Button::south) | button_bit(Button::east);
// A d-pad direction held this long (simulation time from its press edge) repeats,
// then once every kRepeatIntervalNs while still held.
inline constexpr std::int64_t kRepeatDelayNs = 500'000'000;
inline constexpr std::int64_t kRepeatIntervalNs = 100'000'000;

// Turns press events and held buttons into discrete steps, one frame at a time:
// a frame that shows steps "down" is followed by a frame that shows nothing
// (releasing()), so ImGui sees every step as a fresh press (its own repeat,
// timed by summing frame times, never starts). Plain data; no clock.
class PadStepper {
public:
    // True when the last frame showed a step: this frame shows the release, and
    // the caller takes no press event from its queue for it.
    bool releasing() const { return shown_ != 0; }

    // One frame. `press`: the press event taken for this frame (event 0: none).
    // `held`, `held_tick`: the newest tick's buttons and that tick's number;
    // `tick_ns`: a tick's length; `caught_up`: the press queue is empty, so
    // `held` is not ahead of a press still queued. Returns the kStepButtons bits
    // ImGui sees down in this frame (0 on a releasing frame).
    std::uint32_t frame(PadPress press, std::uint32_t held, std::uint64_t held_tick, std::int64_t tick_ns,
                        bool caught_up);

private:
    static constexpr int kDirections = 4;
    std::uint32_t shown_ = 0;  // what the last frame showed
    std::array<bool, kDirections> tracked_{};        // pressed and, as far as we know, still held
    std::array<std::uint64_t, kDirections> down_tick_{};
    std::array<std::int64_t, kDirections> repeats_{};  // repeats shown since the press edge
};

}  // namespace marionette::ui
