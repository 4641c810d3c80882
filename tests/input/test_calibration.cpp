// Calibration maths (centre, range, inversion, radial deadzone, anti-deadzone,
// response curve, triggers) and the config/input.toml loader's errors.
#include <catch2/catch.hpp>

#include <cmath>

#include "input/calibration.hpp"
#include "runtime/errors/import_error.hpp"
#include "tests/test_support.hpp"

using namespace marionette;
using namespace marionette::input;

namespace {
void stick(const FamilyCalibration& cal, bool raw, float x, float y, float& ox, float& oy) {
    ox = x;
    oy = y;
    calibrate_stick(cal, cal.left, raw, ox, oy);
}
}  // namespace

TEST_CASE("calibration: radial deadzone rescales so the edge of the zone reads 0", "[input][calibration]") {
    FamilyCalibration cal;
    cal.stick_deadzone = 0.1f;
    float x, y;
    stick(cal, false, 0.09f, 0.0f, x, y);
    CHECK(x == 0.0f);
    CHECK(y == 0.0f);
    stick(cal, false, 0.55f, 0.0f, x, y);
    CHECK(x == Approx(0.5));  // (0.55 - 0.1) / 0.9
    // Radial, not per axis: each axis inside the zone, the magnitude outside.
    stick(cal, false, 0.08f, 0.08f, x, y);
    CHECK(x > 0.0f);
    CHECK(x == Approx(y));
    CHECK(std::hypot(x, y) == Approx((std::hypot(0.08, 0.08) - 0.1) / 0.9).epsilon(1e-5));
    stick(cal, false, 0.0f, -1.0f, x, y);
    CHECK(y == -1.0f);
}

TEST_CASE("calibration: anti-deadzone and response curve shape the magnitude", "[input][calibration]") {
    FamilyCalibration cal;
    cal.stick_curve = 2.0f;
    float x, y;
    stick(cal, false, 0.5f, 0.0f, x, y);
    CHECK(x == Approx(0.25));
    cal.stick_curve = 1.0f;
    cal.stick_anti_deadzone = 0.2f;
    cal.stick_deadzone = 0.1f;
    stick(cal, false, 0.1001f, 0.0f, x, y);
    CHECK(x == Approx(0.2).margin(1e-3));  // just outside the zone: the anti-deadzone
    stick(cal, false, 1.0f, 0.0f, x, y);
    CHECK(x == 1.0f);
    stick(cal, false, 0.55f, 0.0f, x, y);
    CHECK(x == Approx(0.2 + 0.8 * 0.5));
}

TEST_CASE("calibration: centre, range and inversion apply in raw mode too, deadzone and curve do not", "[input][calibration]") {
    FamilyCalibration cal;
    cal.left.centre_x = 0.1f;
    cal.left.invert_y = true;
    cal.stick_range = 0.8f;
    cal.stick_deadzone = 0.5f;
    cal.stick_curve = 3.0f;
    float x, y;
    stick(cal, true, 0.1f, 0.4f, x, y);
    CHECK(x == 0.0f);
    CHECK(y == Approx(-0.5));
    stick(cal, true, 0.9f, -0.8f, x, y);  // full range on both axes: a square, not clamped to the circle in raw
    CHECK(x == Approx(1.0));
    CHECK(y == Approx(1.0));
    stick(cal, false, 0.9f, -0.8f, x, y);  // calibrated: clamped to the unit circle
    CHECK(std::hypot(x, y) == Approx(1.0));
}

TEST_CASE("calibration: triggers get a deadzone and a range", "[input][calibration]") {
    FamilyCalibration cal;
    cal.trigger_deadzone = 0.1f;
    cal.trigger_range = 0.8f;
    CHECK(calibrate_trigger(cal, false, 0.05f) == 0.0f);
    CHECK(calibrate_trigger(cal, false, 0.8f) == 1.0f);
    CHECK(calibrate_trigger(cal, false, 0.44f) == Approx((0.55 - 0.1) / 0.9));
    CHECK(calibrate_trigger(cal, true, 0.05f) == Approx(0.0625));  // raw: range only
    CHECK(calibrate_trigger(cal, true, 1.0f) == 1.0f);
}

TEST_CASE("calibration: apply_calibration treats both sticks and both triggers", "[input][calibration]") {
    FamilyCalibration cal;
    cal.right.invert_x = true;
    cal.stick_deadzone = 0.2f;
    InputSample s;
    s.lx = 0.1f;
    s.rx = 0.6f;
    s.lt = 0.5f;
    s.buttons = 5;
    apply_calibration(cal, false, s);
    CHECK(s.lx == 0.0f);
    CHECK(s.rx == Approx(-0.5));
    CHECK(s.lt == 0.5f);
    CHECK(s.buttons == 5u);
}

TEST_CASE("input config: the shipped config/input.toml loads and overrides per family", "[input][calibration]") {
    const std::string text = test::read_text_file(test::source_path("config/input.toml"));
    const InputConfig c = apply_input_config_text(InputConfig{}, text, "config/input.toml");
    CHECK(c.family(DeviceFamily::evdev).stick_deadzone == Approx(0.06));    // [default]
    CHECK(c.family(DeviceFamily::ds4).stick_deadzone == Approx(0.07));      // [ds4]
    CHECK(c.family(DeviceFamily::switchpro).stick_range == Approx(0.95));
    CHECK(c.sdl_mapping_file.empty());
    // A user file on top changes only what it names.
    const InputConfig u = apply_input_config_text(c, "[sdl]\nmapping_file = \"db.txt\"\n[evdev]\ninvert_right_y = true\n", "user.toml");
    CHECK(u.sdl_mapping_file == "db.txt");
    CHECK(u.family(DeviceFamily::evdev).right.invert_y);
    CHECK(u.family(DeviceFamily::ds4).stick_deadzone == Approx(0.07));
}

TEST_CASE("input config: errors name the file, line and key", "[input][calibration]") {
    const auto message = [](const std::string& text) {
        try {
            apply_input_config_text(InputConfig{}, text, "bad.toml");
        } catch (const ImportError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    CHECK(message("[ds4]\n\nstick_deadzone = 2.0\n") ==
          "bad.toml:3: ds4.stick_deadzone: 2.0 is out of range: expected a number in [0.0, 0.9]");
    CHECK_THAT(message("[ps5]\nx = 1\n"), Catch::StartsWith("bad.toml:1: ps5: unknown table"));
    CHECK_THAT(message("[default]\nstick_deadzon = 0.1\n"), Catch::StartsWith("bad.toml:2: default.stick_deadzon: unknown key"));
    CHECK(message("[evdev]\ninvert_left_x = 1\n") == "bad.toml:2: evdev.invert_left_x: expected true or false");
    CHECK_THAT(message("[evdev\n"), Catch::StartsWith("bad.toml:1: TOML syntax error"));
    CHECK_THAT(message("[ds4]\nmapping_file = \"x\"\n"), Catch::Contains("ds4.mapping_file: unknown key"));
}

TEST_CASE("input config: every key is documented in docs/input.md", "[input][calibration]") {
    const std::string doc = test::read_text_file(test::source_path("docs/input.md"));
    for (const InputConfigKey& k : input_config_schema()) {
        INFO(k.key);
        CHECK(doc.find("`" + k.key + "`") != std::string::npos);
    }
}

TEST_CASE("samples quantise exactly as every TickInput producer does", "[input]") {
    InputSample s;
    s.t_ns = 123;
    s.lx = 1.0f;
    s.ly = -1.0f;
    s.rx = 0.5f;
    s.lt = 1.0f;
    s.rt = 0.25f;
    s.buttons = button_bit(Button::south);
    const TimedInput t = to_timed_input(s);
    CHECK(t.timestamp_ns == 123);
    CHECK(t.input.left_x == 32767);
    CHECK(t.input.left_y == -32767);
    CHECK(t.input.right_x == quantize_stick(0.5));
    CHECK(t.input.left_trigger == 65535);
    CHECK(t.input.right_trigger == quantize_trigger(0.25));
    CHECK(t.input.buttons == button_bit(Button::south));
    CHECK(button_list_json(button_bit(Button::south) | button_bit(Button::dpad_right)) == "[\"south\",\"dpad_right\"]");
}

TEST_CASE("normalisation: integer centre, each side reaching exactly 1", "[input]") {
    CHECK(normalise_centred(128, 0, 255) == 0.0f);
    CHECK(normalise_centred(0, 0, 255) == -1.0f);
    CHECK(normalise_centred(255, 0, 255) == 1.0f);
    CHECK(normalise_centred(-32768, -32768, 32767) == -1.0f);
    CHECK(normalise_centred(32767, -32768, 32767) == 1.0f);
    CHECK(normalise_centred(0, -1, 1) == 0.0f);
    CHECK(normalise_centred(500, 0, 255) == 1.0f);  // clamped
    CHECK(normalise_trigger(0, 0, 1023) == 0.0f);
    CHECK(normalise_trigger(1023, 0, 1023) == 1.0f);
    CHECK(normalise_centred(5, 5, 5) == 0.0f);  // a broken absinfo never divides by zero
}
