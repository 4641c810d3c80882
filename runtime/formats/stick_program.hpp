#pragma once
// Stick programs: a small text format that scripts a controller over time, so
// tests and users make input logs without hardware (docs/stick-programs.md).
//
//   # comment
//   hold 1.5s                      keep sticks and triggers as they are
//   hold 2s lx=0 ly=1              set values, then keep them
//   ramp 500ms ly=0.5 lt=1         move linearly from the current values to these
//   circle 4s radius=1 turns=1 from=90 stick=left
//                                  stick goes round (counter-clockwise for turns>0)
//   press south 100ms              hold a button for a while; sticks keep moving
//                                  as the previous segment left them
//
// Values: lx ly rx ry in [-1, 1] (x right, y up), lt rt in [0, 1].
// Durations: a number with `s` or `ms`.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/errors/import_error.hpp"
#include "runtime/sim/tick_input.hpp"

namespace marionette {

struct StickValues {
    double lx = 0, ly = 0, rx = 0, ry = 0, lt = 0, rt = 0;
};

struct StickSegment {
    enum class Kind : std::uint8_t { hold, ramp, circle, press };
    Kind kind = Kind::hold;
    double duration_s = 0.0;
    // hold/ramp: which fields the line set, and to what.
    std::uint8_t set_mask = 0;      // bit i: lx ly rx ry lt rt
    StickValues target;
    // circle
    bool right_stick = false;
    double radius = 1.0;
    double turns = 1.0;
    double from_deg = 90.0;         // start angle; 90° is stick straight up
    // press
    std::uint32_t buttons = 0;
    int line = 0;
};

struct StickProgram {
    std::string name;
    std::vector<StickSegment> segments;
    double duration_s() const;
};

// Throws ImportError naming the file and line on any malformed line.
StickProgram parse_stick_program(std::string_view text, const std::string& file_name);
StickProgram load_stick_program_file(const std::string& path);

// The program sampled at every tick of a rate: tick k covers time [k/rate, (k+1)/rate)
// and takes the program's values at k/rate; a press lasting less than a tick still
// sets its button in the tick it starts in.
std::vector<TickInput> render_stick_program(const StickProgram& program, int tick_rate_hz);

}  // namespace marionette
