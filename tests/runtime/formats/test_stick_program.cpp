#include <catch2/catch.hpp>

#include "runtime/formats/stick_program.hpp"

using namespace marionette;

TEST_CASE("stick programs render to ticks", "[stick_program]") {
    const StickProgram p = parse_stick_program(
        "# test\n"
        "hold 0.5s\n"
        "ramp 1s ly=1   # full up\n"
        "hold 250ms lt=0.5\n"
        "press south 10ms\n"
        "circle 1s radius=0.5 from=0\n",
        "t.prog");
    REQUIRE(p.segments.size() == 5);
    CHECK(p.duration_s() == Approx(2.76));
    const std::vector<TickInput> ticks = render_stick_program(p, 100);
    REQUIRE(ticks.size() == 276);
    CHECK(ticks[0].left_y == 0);
    CHECK(ticks[50].left_y == 0);             // ramp starts from the current value
    CHECK(ticks[100].left_y == quantize_stick(0.5));
    CHECK(ticks[149].left_y == quantize_stick(0.99));
    CHECK(ticks[150].left_y == 32767);
    CHECK(ticks[150].left_trigger == quantize_trigger(0.5));
    CHECK(ticks[175].buttons == button_bit(Button::south));  // a 10 ms press fills its one tick
    CHECK(ticks[174].buttons == 0);
    CHECK(ticks[176].buttons == 0);
    CHECK(ticks[176].left_x == quantize_stick(0.5));          // circle from 0°: stick right
    CHECK(ticks[201].left_y == quantize_stick(0.5));          // a quarter turn later: up
}

TEST_CASE("a press shorter than a tick is not lost", "[stick_program]") {
    const StickProgram p = parse_stick_program("hold 3ms\npress east 1ms\nhold 10ms\n", "short.prog");
    const std::vector<TickInput> ticks = render_stick_program(p, 240);
    int pressed = 0;
    for (const TickInput& t : ticks) pressed += (t.buttons & button_bit(Button::east)) ? 1 : 0;
    CHECK(pressed == 1);
}

TEST_CASE("malformed stick programs name file and line", "[stick_program]") {
    struct Case {
        const char* text;
        int line;
        const char* message;
    };
    const Case cases[] = {
        {"hold 1s\njump 2s\n", 2, "unknown command 'jump'"},
        {"hold\n", 1, "expected a duration"},
        {"hold 1x\n", 1, "expected a duration such as"},
        {"hold -1s\n", 1, "non-negative duration"},
        {"\n\nramp 1s ly=2\n", 3, "out of range"},
        {"ramp 1s zz=0.1\n", 1, "unknown value 'zz'"},
        {"ramp 1s ly=abc\n", 1, "expected a number after 'ly='"},
        {"ramp 1s ly=nan\n", 1, "expected a number"},
        {"press banana\n", 1, "unknown button 'banana'"},
        {"circle 1s stick=middle\n", 1, "stick=left or stick=right"},
        {"circle 1s radius=3\n", 1, "radius must be in [0, 1]"},
        {"hold 7200s\n", 1, "longer than one hour"},
        {"# nothing\n", 1, "no commands"},
        {"hold 1s\n\x01\x02garbage", 2, "control character"},
    };
    for (const Case& c : cases) {
        INFO(c.text);
        try {
            parse_stick_program(c.text, "bad.prog");
            FAIL("no error");
        } catch (const ImportError& e) {
            CHECK(e.file() == "bad.prog");
            CHECK(e.line() == c.line);
            CHECK_THAT(e.message(), Catch::Contains(c.message));
        }
    }
}
