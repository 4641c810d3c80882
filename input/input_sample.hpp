#pragma once
// What every input backend produces: one controller state at one instant, in
// normalised floats, before the pipeline quantises it into a TickInput.
#include <cstdint>
#include <string>

#include "runtime/sim/tick_input.hpp"
#include "runtime/handoff/tick_input_assembler.hpp"

namespace marionette::input {

struct InputSample {
    std::int64_t t_ns = 0;          // CLOCK_MONOTONIC when the input thread read it
    std::uint32_t device_id = 0;    // the backend's slot for the device (stable while plugged)
    float lx = 0, ly = 0;           // left stick in [-1, 1]; x right positive, y up positive
    float rx = 0, ry = 0;           // right stick
    float lt = 0, rt = 0;           // triggers in [0, 1]
    std::uint32_t buttons = 0;      // bit i = runtime Button(i) held
    bool has_device_counter = false;
    std::uint32_t device_counter = 0;  // the report's own sequence number or timestamp
};

// The pipeline's view of a sample: quantised exactly as every other producer
// of TickInputs quantises (runtime/sim/tick_input.hpp).
TimedInput to_timed_input(const InputSample& sample);

// Button names of a mask in Button order ("south", "east", ...).
std::string button_list_json(std::uint32_t buttons);

// Normalisation helpers shared by the parsers and the evdev backend.
// A centred axis: the integer centre is min + (max - min + 1) / 2, so 0..255 has
// centre 128 and -32768..32767 has centre 0; each side scales to reach ±1 exactly
// at its end.
float normalise_centred(std::int32_t value, std::int32_t min, std::int32_t max);
// Negation for axes that grow downwards; never yields -0 (which JSON would print).
inline float flip_axis(float v) { return v == 0.0f ? 0.0f : -v; }
// A one-sided axis (trigger): min → 0, max → 1.
float normalise_trigger(std::int32_t value, std::int32_t min, std::int32_t max);

}  // namespace marionette::input
