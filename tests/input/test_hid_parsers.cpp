// The four HID parsers against hand-written reports with known values, against
// malformed ones, and against firmware_sim's generated reports.
#include <catch2/catch.hpp>

#include <array>
#include <vector>

#include "firmware_sim/report_encoders.hpp"
#include "firmware_sim/sim_hid_device.hpp"
#include "input/hid/ds4.hpp"
#include "input/hid/dualsense.hpp"
#include "input/hid/hid_pad.hpp"
#include "input/hid/steam_deck.hpp"
#include "input/hid/switch_pro.hpp"

using namespace marionette;
using namespace marionette::input;
namespace fs = marionette::firmware_sim;

namespace {
std::uint32_t bits(std::initializer_list<Button> list) {
    std::uint32_t b = 0;
    for (Button x : list) b |= button_bit(x);
    return b;
}
}  // namespace

TEST_CASE("ds4: a hand-written USB report decodes to known values", "[input][hid]") {
    std::array<std::uint8_t, 64> r{};
    r[0] = 0x01;
    r[1] = 0;      // left x: full left
    r[2] = 255;    // left y: full down
    r[3] = 128;    // right x: centre
    r[4] = 0;      // right y: full up
    r[5] = 0x20 | 2;          // cross, hat east
    r[6] = 0x01 | 0x20 | 0x80;  // L1, options, R3
    r[7] = (5 << 2) | 0x01;   // counter 5, PS
    r[8] = 255;
    r[9] = 0;
    InputSample s;
    REQUIRE(ds4::parse(r, s) == ParseStatus::ok);
    CHECK(s.lx == -1.0f);
    CHECK(s.ly == -1.0f);
    CHECK(s.rx == 0.0f);
    CHECK(s.ry == 1.0f);
    CHECK(s.lt == 1.0f);
    CHECK(s.rt == 0.0f);
    CHECK(s.buttons == bits({Button::south, Button::dpad_right, Button::left_shoulder, Button::start,
                             Button::right_stick, Button::guide}));
    CHECK(s.has_device_counter);
    CHECK(s.device_counter == 5);
}

TEST_CASE("ds4: short, long, foreign and garbled reports are rejected", "[input][hid]") {
    std::vector<std::uint8_t> r(64, 0);
    r[0] = 0x01;
    r[5] = 8;  // hat released
    InputSample s;
    CHECK(ds4::parse(r, s) == ParseStatus::ok);
    CHECK(ds4::parse(std::span<const std::uint8_t>(r.data(), 63), s) == ParseStatus::too_short);
    CHECK(ds4::parse(std::span<const std::uint8_t>(r.data(), 0), s) == ParseStatus::too_short);
    std::vector<std::uint8_t> longer = r;
    longer.push_back(0);
    CHECK(ds4::parse(longer, s) == ParseStatus::too_long);
    r[0] = 0x05;
    CHECK(ds4::parse(r, s) == ParseStatus::wrong_report_id);
    r[0] = 0x01;
    r[5] = 0x0C;  // no such hat direction
    CHECK(ds4::parse(r, s) == ParseStatus::garbled);
}

TEST_CASE("ds4 and dualsense: Bluetooth reports are CRC-checked", "[input][hid]") {
    fs::PadState st;
    st.lx = 0.5;
    st.buttons = bits({Button::north});
    for (const HidFormat f : {HidFormat::ds4, HidFormat::dualsense}) {
        fs::Report r = fs::encode_report(f, st, {}, true, switchpro::kDefaultCalibration);
        REQUIRE(r.size == 78);
        InputSample s;
        CHECK(parse_hid_report(f, r.view(), switchpro::kDefaultCalibration, s) == ParseStatus::ok);
        CHECK(s.buttons == bits({Button::north}));
        CHECK(s.lx == Approx(0.5).margin(1.0 / 127));
        r.bytes[20] ^= 0x01;
        CHECK(parse_hid_report(f, r.view(), switchpro::kDefaultCalibration, s) == ParseStatus::garbled);
    }
}

TEST_CASE("dualsense: a hand-written USB report decodes to known values", "[input][hid]") {
    std::array<std::uint8_t, 64> r{};
    r[0] = 0x01;
    r[1] = 255;  // left x full right
    r[2] = 128;  // left y centre
    r[3] = 64;   // right x: -64/128 = -0.5
    r[4] = 192;  // right y: 64/127 down
    r[5] = 0;    // L2
    r[6] = 255;  // R2
    r[7] = 42;   // sequence
    r[8] = 0x10 | 0x40 | 7;  // square, circle, hat north-west
    r[9] = 0x02 | 0x10 | 0x40;  // R1, create, L3
    r[10] = 0x01 | 0x04;        // PS, mute
    InputSample s;
    REQUIRE(dualsense::parse(r, s) == ParseStatus::ok);
    CHECK(s.lx == 1.0f);
    CHECK(s.ly == 0.0f);
    CHECK(s.rx == -0.5f);
    CHECK(s.ry == Approx(-64.0 / 127.0));
    CHECK(s.lt == 0.0f);
    CHECK(s.rt == 1.0f);
    CHECK(s.device_counter == 42);
    CHECK(s.buttons == bits({Button::west, Button::east, Button::dpad_up, Button::dpad_left, Button::right_shoulder,
                             Button::back, Button::left_stick, Button::guide}));
    r[0] = 0x31;  // a BT id at USB length
    CHECK(dualsense::parse(r, s) == ParseStatus::too_short);
}

TEST_CASE("switchpro: 12-bit sticks through the default and the factory calibration", "[input][hid]") {
    std::array<std::uint8_t, 64> r{};
    r[0] = 0x30;
    r[1] = 7;  // timer
    r[3] = switchpro::kB | switchpro::kZR;
    r[4] = switchpro::kPlus | switchpro::kHome;
    r[5] = switchpro::kUp | switchpro::kL;
    // Left stick x = 2048 + 1536 = 3584 (full right), y = 2048 - 768 = 1280 (half down).
    r[6] = 0x00;
    r[7] = 0x0E;
    r[8] = 0x50;
    // Right stick x = 2048 (centre), y = 2048 + 1536 = 3584 (full up).
    r[9] = 0x00;
    r[10] = 0x08;
    r[11] = 0xE0;
    InputSample s;
    REQUIRE(switchpro::parse(r, switchpro::kDefaultCalibration, s) == ParseStatus::ok);
    CHECK(s.lx == 1.0f);
    CHECK(s.ly == -0.5f);
    CHECK(s.rx == 0.0f);
    CHECK(s.ry == 1.0f);
    CHECK(s.lt == 0.0f);
    CHECK(s.rt == 1.0f);
    CHECK(s.device_counter == 7);
    CHECK(s.buttons == bits({Button::south, Button::start, Button::guide, Button::dpad_up, Button::left_shoulder}));

    // Through a factory calibration centred at 2000 with 1584 counts to the right.
    switchpro::Calibration cal = switchpro::kDefaultCalibration;
    cal.left.centre_x = 2000;
    cal.left.x_above = 1584;
    REQUIRE(switchpro::parse(r, cal, s) == ParseStatus::ok);
    CHECK(s.lx == 1.0f);
    cal.left.x_above = 3168;
    REQUIRE(switchpro::parse(r, cal, s) == ParseStatus::ok);
    CHECK(s.lx == 0.5f);

    CHECK(switchpro::parse(std::span<const std::uint8_t>(r.data(), 48), cal, s) == ParseStatus::too_short);
    r[0] = 0x21;
    CHECK(switchpro::parse(r, cal, s) == ParseStatus::ignored);  // a subcommand reply
    r[0] = 0x3F;
    CHECK(switchpro::parse(r, cal, s) == ParseStatus::wrong_report_id);
}

TEST_CASE("switchpro: factory calibration block decodes, encodes back, and blank flash is refused", "[input][hid]") {
    const auto block = switchpro::encode_factory_calibration(fs::kSimSwitchCalibration);
    switchpro::Calibration out = switchpro::kDefaultCalibration;
    REQUIRE(switchpro::decode_factory_calibration(block, out));
    CHECK(out.from_device);
    CHECK(out.left.centre_x == 1990);
    CHECK(out.left.y_above == 1440);
    CHECK(out.right.x_below == 1500);
    CHECK(out.right.y_above == 1550);
    std::array<std::uint8_t, 18> blank;
    blank.fill(0xFF);
    switchpro::Calibration untouched = switchpro::kDefaultCalibration;
    CHECK_FALSE(switchpro::decode_factory_calibration(blank, untouched));
    CHECK(untouched.left.centre_x == 2048);
}

TEST_CASE("switchpro: HidPad reads the factory calibration over the transport, else keeps the defaults", "[input][hid]") {
    StickProgram program = parse_stick_program("hold 10ms lx=1 ly=-1\n", "t.prog");
    fs::SimPadOptions o;
    o.hid_format = HidFormat::switchpro;
    const fs::SimStream stream = fs::simulate_pad(program, o);
    {
        fs::SimHidDevice device(stream, HidFormat::switchpro, fs::kSimSwitchCalibration, true);
        HidPad pad(device, HidFormat::switchpro);
        REQUIRE(pad.initialise(50));
        CHECK(device.spi_reads() == 1);
        CHECK(pad.calibration().from_device);
        CHECK(pad.calibration().left.centre_x == fs::kSimSwitchCalibration.left.centre_x);
        InputSample s;
        REQUIRE(pad.read(s, 0) == HidPad::Result::sample);
        CHECK(s.lx == 1.0f);  // reports were encoded with the same factory calibration
        CHECK(s.ly == -1.0f);
    }
    {
        fs::SimHidDevice device(stream, HidFormat::switchpro, fs::kSimSwitchCalibration, false);
        HidPad pad(device, HidFormat::switchpro);
        REQUIRE(pad.initialise(50));
        CHECK_FALSE(pad.calibration().from_device);
        CHECK(pad.calibration().left.centre_x == switchpro::kDefaultCalibration.left.centre_x);
    }
}

TEST_CASE("steamdeck: a hand-written report decodes to known values", "[input][hid]") {
    std::array<std::uint8_t, 64> r{};
    r[0] = 0x01;
    r[2] = 0x09;
    r[3] = 64;
    r[4] = 0x04; r[5] = 0x03; r[6] = 0x02; r[7] = 0x01;  // packet 0x01020304
    const std::uint32_t lo = steamdeck::kA | steamdeck::kDpadDown | steamdeck::kL3 | steamdeck::kMenu;
    for (int i = 0; i < 4; ++i) r[static_cast<std::size_t>(8 + i)] = static_cast<std::uint8_t>(lo >> (8 * i));
    r[44] = 0xFF; r[45] = 0x7F;  // left trigger 32767
    r[48] = 0x00; r[49] = 0x80;  // left x -32768
    r[50] = 0xFF; r[51] = 0x7F;  // left y 32767 (up)
    r[52] = 0x00; r[53] = 0x40;  // right x 16384
    InputSample s;
    REQUIRE(steamdeck::parse(r, s) == ParseStatus::ok);
    CHECK(s.lx == -1.0f);
    CHECK(s.ly == 1.0f);
    CHECK(s.rx == Approx(16384.0 / 32767.0));
    CHECK(s.ry == 0.0f);
    CHECK(s.lt == 1.0f);
    CHECK(s.rt == 0.0f);
    CHECK(s.device_counter == 0x01020304u);
    CHECK(s.buttons == bits({Button::south, Button::dpad_down, Button::left_stick, Button::start}));
    r[3] = 63;
    CHECK(steamdeck::parse(r, s) == ParseStatus::garbled);
    r[3] = 64;
    r[2] = 0x04;  // another message type
    CHECK(steamdeck::parse(r, s) == ParseStatus::ignored);
    CHECK(steamdeck::parse(std::span<const std::uint8_t>(r.data(), 60), s) == ParseStatus::too_short);
}

TEST_CASE("steamdeck: HidPad turns lizard mode off and feeds the watchdog", "[input][hid]") {
    StickProgram program = parse_stick_program("hold 450ms lx=0.5\n", "t.prog");
    fs::SimPadOptions o;
    o.hid_format = HidFormat::steamdeck;
    fs::SimHidDevice device(fs::simulate_pad(program, o), HidFormat::steamdeck);
    CHECK(device.lizard_mode());
    HidPad pad(device, HidFormat::steamdeck);
    REQUIRE(pad.initialise(10));
    CHECK_FALSE(device.lizard_mode());
    CHECK(device.lizard_settings_received() == 1);
    InputSample s;
    int samples = 0;
    while (pad.read(s, 0) == HidPad::Result::sample) ++samples;
    CHECK(samples == 450);
    CHECK(device.lizard_settings_received() == 1 + 450 / steamdeck::kWatchdogReports);
}

TEST_CASE("every format: firmware_sim reports parse back to the state they encode", "[input][hid][firmware_sim]") {
    const fs::PadState states[] = {
        {0, 0, 0, 0, 0, 0, 0},
        {1, -1, -1, 1, 1, 1, bits({Button::south, Button::east, Button::west, Button::north})},
        {0.25, 0.5, -0.75, -0.125, 0.3, 0.6, bits({Button::dpad_up, Button::dpad_left, Button::back, Button::start})},
        {-0.5, -0.25, 0.5, 0.75, 0, 1, bits({Button::left_shoulder, Button::right_shoulder, Button::left_stick,
                                            Button::right_stick, Button::guide, Button::dpad_down, Button::dpad_right})},
    };
    for (int f = 0; f < kHidFormatCount; ++f) {
        const auto format = static_cast<HidFormat>(f);
        INFO(hid_format_name(format));
        // Quantisation step of each format's sticks.
        const double step = format == HidFormat::steamdeck ? 1.0 / 32767 : format == HidFormat::switchpro ? 1.0 / 1536 : 1.0 / 127;
        fs::ReportClock clock;
        for (const fs::PadState& st : states) {
            const fs::Report r = fs::encode_report(format, st, clock, false, switchpro::kDefaultCalibration);
            InputSample s;
            REQUIRE(parse_hid_report(format, r.view(), switchpro::kDefaultCalibration, s) == ParseStatus::ok);
            CHECK(s.buttons == st.buttons);
            CHECK(s.lx == Approx(st.lx).margin(step));
            CHECK(s.ly == Approx(st.ly).margin(step));
            CHECK(s.rx == Approx(st.rx).margin(step));
            CHECK(s.ry == Approx(st.ry).margin(step));
            if (format == HidFormat::switchpro) {  // digital triggers
                CHECK(s.lt == (st.lt >= 0.5 ? 1.0f : 0.0f));
                CHECK(s.rt == (st.rt >= 0.5 ? 1.0f : 0.0f));
            } else {
                CHECK(s.lt == Approx(st.lt).margin(1.0 / 255));
                CHECK(s.rt == Approx(st.rt).margin(1.0 / 255));
            }
            ++clock.counter;
        }
    }
}

TEST_CASE("parser counters count each kind of rejection", "[input][hid]") {
    ParseCounters c;
    for (ParseStatus s : {ParseStatus::ok, ParseStatus::ok, ParseStatus::too_short, ParseStatus::too_long,
                          ParseStatus::wrong_report_id, ParseStatus::garbled, ParseStatus::ignored})
        c.count(s);
    CHECK(c.accepted == 2);
    CHECK(c.rejected() == 4);
    CHECK(c.ignored == 1);
}

TEST_CASE("supported pads are recognised by vendor, product and interface", "[input][hid]") {
    CHECK(find_hid_device_kind(0x054c, 0x0ce6, 3)->format == HidFormat::dualsense);
    CHECK(find_hid_device_kind(0x054c, 0x09cc, -1)->format == HidFormat::ds4);
    CHECK(find_hid_device_kind(0x057e, 0x2009, 0)->format == HidFormat::switchpro);
    CHECK(find_hid_device_kind(0x28de, 0x1205, 2)->format == HidFormat::steamdeck);
    CHECK_FALSE(find_hid_device_kind(0x28de, 0x1205, 0));  // the Deck's keyboard/mouse interfaces
    CHECK_FALSE(find_hid_device_kind(0x045e, 0x028e, 0));
}
