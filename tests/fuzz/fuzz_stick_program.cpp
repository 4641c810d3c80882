// Stick programs: parse, then render at 240 Hz when the program is at most 60 s
// long (a valid program may last 24 h: that is time, not a finding). Every
// rendered value is inside the TickInput ranges the quantiser promises.
#include "runtime/formats/stick_program.hpp"
#include "tests/fuzz/fuzz_support.hpp"

using namespace marionette;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    StickProgram program;
    try {
        program = parse_stick_program(fuzz::as_text(data, size), "fuzz.prog");
    } catch (const ImportError&) {
        return 0;
    }
    if (!(program.duration_s() <= 60.0)) return 0;
    const std::vector<TickInput> ticks = render_stick_program(program, 240);
    fuzz::fuzz_check(ticks.size() <= 60 * 240 + program.segments.size() + 1, "more ticks than the program lasts");
    for (const TickInput& t : ticks) {
        fuzz::fuzz_check(t.left_x >= -32767 && t.left_y >= -32767 && t.right_x >= -32767 && t.right_y >= -32767,
                         "stick value below -32767");
    }
    return 0;
}
