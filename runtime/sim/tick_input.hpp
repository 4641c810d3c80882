#pragma once
// What the simulation consumes each tick: integers only, so the tick is a pure
// function of exactly these bits. Floats are derived inside the tick.
#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

namespace marionette {

struct TickInput {
    std::int16_t left_x = 0;    // right positive
    std::int16_t left_y = 0;    // up positive
    std::int16_t right_x = 0;
    std::int16_t right_y = 0;
    std::uint16_t left_trigger = 0;
    std::uint16_t right_trigger = 0;
    std::uint32_t buttons = 0;  // bit i = Button(i) held or pressed during the tick

    friend bool operator==(const TickInput&, const TickInput&) = default;
};

// Positional button names (SDL style: south is the bottom face button whatever
// its label). The bit index is the enum value.
enum class Button : std::uint8_t {
    south, east, west, north, left_shoulder, right_shoulder, back, start, guide,
    left_stick, right_stick, dpad_up, dpad_down, dpad_left, dpad_right,
};
inline constexpr int kButtonCount = 15;
inline constexpr std::array<std::string_view, kButtonCount> kButtonNames = {
    "south", "east", "west", "north", "left_shoulder", "right_shoulder", "back", "start", "guide",
    "left_stick", "right_stick", "dpad_up", "dpad_down", "dpad_left", "dpad_right",
};

inline constexpr std::uint32_t button_bit(Button b) { return 1u << static_cast<unsigned>(b); }

inline std::optional<Button> button_from_name(std::string_view name) {
    for (int i = 0; i < kButtonCount; ++i)
        if (kButtonNames[static_cast<size_t>(i)] == name) return static_cast<Button>(i);
    return std::nullopt;
}

// Stick and trigger quantisation shared by every producer of TickInputs.
inline constexpr float kStickScale = 32767.0f;
inline constexpr float kTriggerScale = 65535.0f;
std::int16_t quantize_stick(double value);     // [-1, 1] → [-32767, 32767], clamped
std::uint16_t quantize_trigger(double value);  // [0, 1] → [0, 65535], clamped

}  // namespace marionette
