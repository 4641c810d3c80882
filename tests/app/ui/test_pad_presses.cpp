// The tuning UI's pad steps (app/ui/pad_presses.hpp): a press edge is exactly one
// step whatever the frame times, and a held d-pad repeats only by the simulation
// time counted from its press edge. The render thread's protocol is reproduced
// here as in app/live/pipeline.cpp (feed_tuning_ui): one queued press a frame,
// none on a releasing frame, held buttons counted only once the queue is empty.
#include <catch2/catch.hpp>

#include <array>
#include <cstdint>
#include <deque>
#include <random>
#include <vector>

#include "app/ui/pad_presses.hpp"

using namespace marionette;
using ui::PadPress;
using ui::PadStepper;

namespace {

constexpr std::int64_t kTickNs = 8'333'333;  // 120 Hz

// Buttons held in each tick (tick i+1 in PuppetState numbering).
using Tape = std::vector<std::uint32_t>;

// Per frame: how many new ticks arrived before it (0: a frame with no new tick).
struct Run {
    std::array<int, 32> steps{};  // steps shown per button bit
    int frames = 0;
};

Run play(const Tape& tape, const std::vector<int>& ticks_per_frame) {
    PadStepper stepper;
    std::deque<PadPress> queue;
    Run run;
    std::size_t next_tick = 0;
    std::uint32_t previous = 0;
    auto one_frame = [&](int new_ticks) {
        for (int t = 0; t < new_ticks && next_tick < tape.size(); ++t, ++next_tick) {
            const std::uint32_t event = ui::press_event(previous, tape[next_tick]);
            if (event != 0) queue.push_back(PadPress{event, next_tick + 1});
            previous = tape[next_tick];
        }
        PadPress press{};
        if (!stepper.releasing() && !queue.empty()) {
            press = queue.front();
            queue.pop_front();
        }
        const std::uint32_t shown = stepper.frame(press, previous, next_tick, kTickNs, queue.empty());
        for (int b = 0; b < 32; ++b)
            if (shown & (1u << b)) ++run.steps[static_cast<std::size_t>(b)];
        ++run.frames;
    };
    for (int n : ticks_per_frame) one_frame(n);
    while (next_tick < tape.size()) one_frame(1);
    for (int i = 0; i < 4 || !queue.empty() || stepper.releasing(); ++i) one_frame(0);  // drain
    return run;
}

int bit_index(Button b) { return static_cast<int>(b); }

std::array<int, 32> press_edges(const Tape& tape) {
    std::array<int, 32> out{};
    std::uint32_t previous = 0;
    for (std::uint32_t now : tape) {
        const std::uint32_t down = now & ~previous;
        for (int b = 0; b < 32; ++b)
            if (down & (1u << b)) ++out[static_cast<std::size_t>(b)];
        previous = now;
    }
    return out;
}

}  // namespace

TEST_CASE("pad steps: one step per press with 0 ms and 500 ms frames, never a repeat from a short tap",
          "[ui][pad]") {
    const std::array<Button, 6> buttons = {Button::dpad_up, Button::dpad_down, Button::dpad_left,
                                           Button::dpad_right, Button::south, Button::east};
    std::mt19937 rng(19);  // fixed seed
    for (int c = 0; c < 300; ++c) {
        // Taps of 1..60 ticks (up to 500 ms held, under the repeat delay) with
        // gaps of 1..90 ticks, of one random step button each.
        Tape tape;
        const int taps = 1 + static_cast<int>(rng() % 12);
        for (int t = 0; t < taps; ++t) {
            const int gap = 1 + static_cast<int>(rng() % 90);
            const int hold = 1 + static_cast<int>(rng() % 60);
            const std::uint32_t bit = button_bit(buttons[rng() % buttons.size()]);
            tape.insert(tape.end(), static_cast<std::size_t>(gap), 0u);
            tape.insert(tape.end(), static_cast<std::size_t>(hold), bit);
        }
        tape.insert(tape.end(), 10, 0u);
        // Frames 0 ms (no new tick) to 500 ms (60 ticks) apart, in runs of the same
        // length and mixed, as a stalled llvmpipe frame after quick ones would be.
        std::vector<int> frames;
        const int style = c % 3;
        for (std::size_t covered = 0; covered < tape.size();) {
            const int n = style == 0   ? (rng() % 2 == 0 ? 0 : 60)
                          : style == 1 ? static_cast<int>(rng() % 61)
                                       : (rng() % 8 == 0 ? 60 : static_cast<int>(rng() % 2));
            frames.push_back(n);
            covered += static_cast<std::size_t>(n);
        }
        const Run run = play(tape, frames);
        const std::array<int, 32> edges = press_edges(tape);
        for (Button b : buttons) {
            INFO("case " << c << ", button " << bit_index(b) << ", frame style " << style);
            CHECK(run.steps[static_cast<std::size_t>(bit_index(b))] == edges[static_cast<std::size_t>(bit_index(b))]);
        }
    }
}

TEST_CASE("pad steps: a held d-pad repeats by the hold's simulation time from its press edge", "[ui][pad]") {
    // Held in 122 ticks (the last 1.008 s after the press edge's): the press, then
    // a repeat at 0.5 s and one every 0.1 s after it: 0.5 0.6 0.7 0.8 0.9 1.0.
    Tape tape(5, 0u);
    tape.insert(tape.end(), 122, button_bit(Button::dpad_right));
    tape.insert(tape.end(), 30, 0u);
    const auto index = static_cast<std::size_t>(bit_index(Button::dpad_right));
    SECTION("frames every tick: every repeat due is shown") {
        const Run run = play(tape, std::vector<int>(tape.size(), 1));
        CHECK(run.steps[index] == 1 + 6);
    }
    SECTION("0 ms frames between the ticks change nothing") {
        std::vector<int> frames;
        for (std::size_t i = 0; i < tape.size(); ++i) frames.insert(frames.end(), {0, 0, 1, 0});
        const Run run = play(tape, frames);
        CHECK(run.steps[index] == 1 + 6);
    }
    SECTION("500 ms frames: never more steps than the hold time allows") {
        const Run run = play(tape, std::vector<int>(tape.size() / 60 + 1, 60));
        CHECK(run.steps[index] >= 1);
        CHECK(run.steps[index] <= 1 + 6);
    }
    SECTION("south and east never repeat") {
        Tape held(5, 0u);
        held.insert(held.end(), 400, button_bit(Button::south) | button_bit(Button::east));
        held.insert(held.end(), 5, 0u);
        const Run run = play(held, std::vector<int>(held.size(), 1));
        CHECK(run.steps[static_cast<std::size_t>(bit_index(Button::south))] == 1);
        CHECK(run.steps[static_cast<std::size_t>(bit_index(Button::east))] == 1);
    }
}
