// firmware_sim: report rates, each seeded fault, determinism, evemu streams, and
// the in-process path HID device -> HidPad -> calibration -> SPSC ring -> tick.
#include <catch2/catch.hpp>

#include <cmath>
#include <chrono>
#include <thread>
#include <set>

#include "firmware_sim/faults.hpp"
#include "firmware_sim/sim_hid_device.hpp"
#include "firmware_sim/sim_pad.hpp"
#include "input/calibration.hpp"
#include "input/hid/hid_pad.hpp"
#include "input/input_thread.hpp"
#include "runtime/errors/import_error.hpp"
#include "runtime/handoff/tick_input_assembler.hpp"
#include "tests/alloc_counter.hpp"

using namespace marionette;
using namespace marionette::input;
namespace fs = marionette::firmware_sim;


namespace {
StickProgram one_second() { return parse_stick_program("ramp 500ms lx=1 ly=0.5\nhold 500ms\n", "t.prog"); }

fs::SimStream run(HidFormat format, int rate, const std::string& faults = "") {
    fs::SimPadOptions o;
    o.hid_format = format;
    o.rate_hz = rate;
    o.faults = fs::parse_faults(faults);
    return fs::simulate_pad(one_second(), o);
}

std::vector<const fs::SimFrame*> reports(const fs::SimStream& s) {
    std::vector<const fs::SimFrame*> out;
    for (const auto& f : s.frames)
        if (f.kind == fs::SimFrame::Kind::report) out.push_back(&f);
    return out;
}
}  // namespace

TEST_CASE("firmware_sim: reports come at exactly the requested rate, 125 Hz to 8 kHz", "[firmware_sim]") {
    for (const int rate : {125, 250, 500, 1000, 4000, 8000}) {
        INFO(rate);
        const fs::SimStream s = run(HidFormat::dualsense, rate);
        const auto r = reports(s);
        REQUIRE(r.size() == static_cast<std::size_t>(rate));  // one second of program
        for (std::size_t k = 1; k < r.size(); ++k) {
            const std::int64_t want = static_cast<std::int64_t>(std::llround(static_cast<double>(k) * 1e9 / rate));
            REQUIRE(r[k]->t_ns == want);
        }
        // The device counter counts every report.
        InputSample last;
        REQUIRE(parse_hid_report(HidFormat::dualsense, r.back()->report.view(), switchpro::kDefaultCalibration, last) ==
                ParseStatus::ok);
        CHECK(last.device_counter == static_cast<std::uint32_t>((rate - 1) & 0xFF));
    }
    CHECK_THROWS_AS(run(HidFormat::ds4, 100), std::invalid_argument);
    CHECK_THROWS_AS(run(HidFormat::ds4, 8001), std::invalid_argument);
}

TEST_CASE("firmware_sim: drop and duplicate faults show in the device counter", "[firmware_sim]") {
    const fs::SimStream s = run(HidFormat::steamdeck, 1000, "drop=0.05,dup=0.02,seed=3");
    CHECK(s.stats.dropped > 20);
    CHECK(s.stats.dropped < 80);
    CHECK(s.stats.duplicated > 5);
    CHECK(s.stats.duplicated < 40);
    std::uint64_t gaps = 0, repeats = 0;
    std::uint32_t previous = 0;
    bool first = true;
    for (const auto* f : reports(s)) {
        InputSample x;
        REQUIRE(parse_hid_report(HidFormat::steamdeck, f->report.view(), switchpro::kDefaultCalibration, x) == ParseStatus::ok);
        if (!first) {
            if (x.device_counter == previous) ++repeats;
            else gaps += x.device_counter - previous - 1;
        }
        first = false;
        previous = x.device_counter;
    }
    CHECK(repeats == s.stats.duplicated);
    CHECK(gaps + (reports(s).front()->report.bytes[4]) == s.stats.dropped);  // drops before the first report count too
    CHECK(s.stats.reports == 1000 - s.stats.dropped + s.stats.duplicated);
}

TEST_CASE("firmware_sim: corrupted reports keep their length and are all rejected", "[firmware_sim]") {
    for (int f = 0; f < kHidFormatCount; ++f) {
        const auto format = static_cast<HidFormat>(f);
        INFO(hid_format_name(format));
        const fs::SimStream s = run(format, 1000, "corrupt=0.03,seed=11");
        REQUIRE(s.stats.corrupted > 5);
        ParseCounters counters;
        for (const auto* r : reports(s)) {
            InputSample x;
            CHECK(r->report.size == 64);
            const ParseStatus st = parse_hid_report(format, r->report.view(), switchpro::kDefaultCalibration, x);
            counters.count(st);
            CHECK((st == ParseStatus::ok) == !r->corrupted);
        }
        CHECK(counters.rejected() == s.stats.corrupted);
    }
}

TEST_CASE("firmware_sim: jitter moves report times within bounds, in order", "[firmware_sim]") {
    const fs::SimStream s = run(HidFormat::ds4, 1000, "jitter=200us,seed=5");
    double max_dev = 0;
    std::int64_t last = -1;
    const auto r = reports(s);
    for (std::size_t k = 0; k < r.size(); ++k) {
        const double dev = std::fabs(static_cast<double>(r[k]->t_ns) - static_cast<double>(k) * 1e6);
        max_dev = std::max(max_dev, dev);
        CHECK(r[k]->t_ns >= last);
        last = r[k]->t_ns;
    }
    CHECK(max_dev <= 200'000.0 + 1.0);
    CHECK(max_dev > 100'000.0);  // it does jitter
}

TEST_CASE("firmware_sim: noise, drift and quantisation change the stick values as asked", "[firmware_sim]") {
    const StickProgram rest = parse_stick_program("hold 1s\n", "rest.prog");
    fs::SimPadOptions o;
    o.hid_format = HidFormat::steamdeck;
    o.faults = fs::parse_faults("noise=0.05,seed=9");
    fs::SimStream s = fs::simulate_pad(rest, o);
    double sum = 0, sum2 = 0;
    for (const auto* f : reports(s)) {
        sum += f->state.lx;
        sum2 += f->state.lx * f->state.lx;
    }
    const double n = static_cast<double>(reports(s).size());
    CHECK(sum / n == Approx(0.0).margin(0.01));
    CHECK(std::sqrt(sum2 / n) == Approx(0.05).epsilon(0.15));

    o.faults = fs::parse_faults("drift=0.1");
    s = fs::simulate_pad(rest, o);
    CHECK(reports(s).front()->state.ly == 0.0);
    CHECK(reports(s).back()->state.ly == Approx(0.1));

    o.faults = fs::parse_faults("quant=4,noise=0.3,seed=2");  // 7 levels each side of 0
    s = fs::simulate_pad(rest, o);
    for (const auto* f : reports(s)) {
        const double v = f->state.rx * 7.0;
        REQUIRE(v == Approx(std::round(v)).margin(1e-9));
    }
}

TEST_CASE("firmware_sim: unplug leaves a gap and replugs after the delay", "[firmware_sim]") {
    const fs::SimStream s = run(HidFormat::dualsense, 1000, "unplug=300ms+200ms");
    CHECK(s.stats.unplugs == 1);
    CHECK(reports(s).size() == 800);
    std::int64_t unplug_t = -1, replug_t = -1;
    for (const auto& f : s.frames) {
        if (f.kind == fs::SimFrame::Kind::unplug) unplug_t = f.t_ns;
        if (f.kind == fs::SimFrame::Kind::replug) replug_t = f.t_ns;
        if (f.kind == fs::SimFrame::Kind::report) CHECK((f.t_ns < 300'000'000 || f.t_ns >= 500'000'000));
    }
    CHECK(unplug_t == 300'000'000);
    CHECK(replug_t == 500'000'000);

    // Through the in-process device: reads fail from the unplug until replug().
    fs::SimHidDevice device(s, HidFormat::dualsense);
    HidPad pad(device, HidFormat::dualsense);
    InputSample x;
    int before = 0;
    HidPad::Result r;
    while ((r = pad.read(x, 0)) == HidPad::Result::sample) ++before;
    CHECK(before == 300);
    CHECK(r == HidPad::Result::disconnected);
    CHECK(pad.read(x, 0) == HidPad::Result::disconnected);
    REQUIRE(device.replug());
    int after = 0;
    while (pad.read(x, 0) == HidPad::Result::sample) ++after;
    CHECK(after == 500);
    CHECK(x.device_counter == 499 % 256);  // the replugged pad counts from 0 again
}

TEST_CASE("firmware_sim: the same seed gives the same bytes, another seed others", "[firmware_sim]") {
    const std::string faults = "noise=0.02,jitter=50us,drop=0.01,dup=0.01,corrupt=0.01";
    const auto a = fs::concatenate_reports(run(HidFormat::ds4, 2000, faults + ",seed=1"));
    const auto b = fs::concatenate_reports(run(HidFormat::ds4, 2000, faults + ",seed=1"));
    const auto c = fs::concatenate_reports(run(HidFormat::ds4, 2000, faults + ",seed=2"));
    CHECK(a == b);
    CHECK(a != c);
}

TEST_CASE("firmware_sim: fault lists are parsed strictly", "[firmware_sim]") {
    const fs::FaultSpec f = fs::parse_faults("noise=0.01,unplug=2s+500ms,syn_dropped=1.5s,syn_dropped=3s,quant=8,seed=4");
    CHECK(f.noise == 0.01);
    CHECK(f.unplug_at_s == 2.0);
    CHECK(f.unplug_for_s == 0.5);
    CHECK(f.syn_dropped_at_s.size() == 2);
    CHECK(f.quant_bits == 8);
    CHECK(f.seed == 4);
    CHECK_FALSE(fs::parse_faults("").any());
    const auto error = [](const std::string& list) {
        try {
            fs::parse_faults(list);
        } catch (const ImportError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    CHECK(error("drop=1.5") == "--faults: 'drop=1.5': expected a probability in [0, 1]");
    CHECK(error("jitter=5") == "--faults: 'jitter=5': expected a duration with a unit (s, ms or us)");
    CHECK_THAT(error("wobble=1"), Catch::Contains("unknown fault"));
    CHECK_THAT(error("unplug=1s"), Catch::Contains("expected unplug=AT+FOR"));
    CHECK_THAT(error("quant=1"), Catch::Contains("[2, 16]"));
}

TEST_CASE("firmware_sim: evemu streams send only changes, one SYN_REPORT per frame", "[firmware_sim]") {
    const StickProgram p = parse_stick_program("hold 5ms\nhold 3ms lx=1\npress south 2ms\nhold 5ms\n", "e.prog");
    fs::SimPadOptions o;
    o.rate_hz = 1000;
    o.faults = fs::parse_faults("syn_dropped=12ms");
    const fs::SimStream s = fs::simulate_pad(p, o);
    const std::string text = fs::write_evemu_stream(s, fs::evdev_pad_description(fs::EvdevPadModel::xbox));
    CHECK(text.rfind("# EVEMU 1.3\n", 0) == 0);
    CHECK(text.find("N: Microsoft X-Box 360 pad\n") != std::string::npos);
    CHECK(text.find("E: 0.005000 0003 0000 32767\nE: 0.005000 0000 0000 0\n") != std::string::npos);  // ABS_X full right
    CHECK(text.find("E: 0.008000 0001 0130 1\nE: 0.008000 0000 0000 0\n") != std::string::npos);      // BTN_SOUTH down
    CHECK(text.find("E: 0.010000 0001 0130 0\n") != std::string::npos);                                // and up
    CHECK(text.find("E: 0.012000 0000 0003 0\nE: 0.012000 0000 0000 0\n") != std::string::npos);      // SYN_DROPPED
    std::size_t syn_reports = 0;
    for (std::size_t at = 0; (at = text.find(" 0000 0000 0\n", at)) != std::string::npos; ++at) ++syn_reports;
    CHECK(syn_reports == 4);  // stick, press, release, the end of the dropped packet (nothing changes after it)
    const std::string ds = fs::write_evemu_stream(s, fs::evdev_pad_description(fs::EvdevPadModel::dualsense));
    CHECK(ds.find("E: 0.005000 0003 0000 255\n") != std::string::npos);
}

TEST_CASE("in-process: a press shorter than a tick reaches the tick through the ring", "[firmware_sim][input]") {
    // 1 kHz reports, a 1 ms press, a 240 Hz simulation: the assembler ORs the
    // buttons of every sample in the tick, so the press survives.
    const StickProgram p = parse_stick_program("hold 10ms lx=0.5\npress east 1ms\nhold 20ms\n", "p.prog");
    fs::SimPadOptions o;
    o.hid_format = HidFormat::dualsense;
    o.rate_hz = 1000;
    fs::SimHidDevice device(fs::simulate_pad(p, o), HidFormat::dualsense);
    HidPad pad(device, HidFormat::dualsense);
    REQUIRE(pad.initialise(10));
    FamilyCalibration cal;
    cal.stick_deadzone = 0.1f;
    static InputRing ring;
    InputRingWriter<InputRing> writer(ring);
    InputSample s;
    std::int64_t t = 0;
    while (pad.read(s, 0) == HidPad::Result::sample) {
        s.t_ns = t;  // the input thread stamps the read time; here, the report's slot
        t += 1'000'000;
        apply_calibration(cal, false, s);
        REQUIRE(writer.push(to_timed_input(s)));
    }
    CHECK(t == 31'000'000);
    TickInputAssembler assembler;
    InputLatencyHistogram stats;
    int ticks_with_east = 0;
    TickInput last{};
    for (int k = 1; k <= 8; ++k) {
        const std::int64_t tick_time = static_cast<std::int64_t>(k) * 1'000'000'000 / 240;
        last = assembler.assemble(ring, tick_time, tick_time, stats);
        if (last.buttons & button_bit(Button::east)) ++ticks_with_east;
    }
    CHECK(ticks_with_east == 1);
    // 0.5 is 192 on the wire (64/127 from centre); the deadzone rescales it.
    CHECK(last.left_x == Approx(32767.0 * (64.0 / 127.0 - 0.1) / 0.9).margin(2));
    CHECK(stats.count == 31);
}

TEST_CASE("hot path: read, parse, calibrate, quantise and push allocate nothing", "[firmware_sim][input]") {
    const StickProgram p = parse_stick_program("circle 1s radius=1\npress south 10ms\n", "a.prog");
    for (int f = 0; f < kHidFormatCount; ++f) {
        const auto format = static_cast<HidFormat>(f);
        INFO(hid_format_name(format));
        fs::SimPadOptions o;
        o.hid_format = format;
        o.faults = fs::parse_faults("corrupt=0.05,noise=0.01");
        fs::SimHidDevice device(fs::simulate_pad(p, o), format);
        HidPad pad(device, format);
        REQUIRE(pad.initialise(10));
        FamilyCalibration cal;
        cal.stick_deadzone = 0.1f;
        cal.stick_curve = 1.7f;
        static InputRing ring;
        InputRingWriter<InputRing> writer(ring);
        TimedInput drained;
        InputSample s;
        int samples = 0;
        const std::uint64_t before = test::allocation_count();
        for (;;) {
            const HidPad::Result r = pad.read(s, 0);
            if (r == HidPad::Result::nothing && device.finished()) break;
            if (r != HidPad::Result::sample) continue;
            apply_calibration(cal, false, s);
            writer.push(to_timed_input(s));
            ring.try_pop(drained);
            ++samples;
        }
        CHECK(test::allocation_count() == before);
        CHECK(samples > 900);
        CHECK(pad.counters().rejected() > 20);
    }
}

TEST_CASE("input thread, hidraw: an unplugged pad is looked for again and read when it is back", "[firmware_sim][input]") {
    // First pad: 300 reports, then unplugged. The next look finds nothing; the
    // one after finds the pad again (a fresh device, as a replugged hidraw node is).
    const fs::SimStream first = run(HidFormat::dualsense, 1000, "unplug=300ms+10s");
    const fs::SimStream second = run(HidFormat::dualsense, 500);
    int opens = 0;
    std::vector<std::unique_ptr<fs::SimHidDevice>> handed_out;
    InputThreadOptions options;
    options.backend = "hidraw";
    options.hid_reopen_interval_ms = 1;
    options.open_hid = [&](const std::string&, OpenedHidPad& opened) {
        ++opens;
        if (opens == 2) return Outcome::failure("unplugged");
        opened.format = HidFormat::dualsense;
        opened.path = "sim" + std::to_string(opens);
        // The thread owns what it is handed; a forwarding transport keeps the
        // device alive here so the test can look at it afterwards.
        struct Forward final : HidTransport {
            fs::SimHidDevice& d;
            explicit Forward(fs::SimHidDevice& device) : d(device) {}
            int read_report(std::span<std::uint8_t> b, int t) override { return d.read_report(b, t); }
            int write_report(std::span<const std::uint8_t> r) override { return d.write_report(r); }
            int send_feature(std::span<const std::uint8_t> r) override { return d.send_feature(r); }
            int get_feature(std::span<std::uint8_t> b) override { return d.get_feature(b); }
        };
        handed_out.push_back(std::make_unique<fs::SimHidDevice>(opens == 1 ? first : second, opened.format));
        opened.transport = std::make_unique<Forward>(*handed_out.back());
        return Outcome::success();
    };
    static InputRing ring;
    InputThread thread;
    REQUIRE(thread.start(ring, options).ok());
    // Drain the ring while waiting for every report of both pads (bounded wait:
    // the thread reads as fast as the in-process devices answer).
    int connected_samples = 0, disconnect_markers = 0;
    TimedInput in;
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (connected_samples < 800 && std::chrono::steady_clock::now() < give_up) {
        while (ring.try_pop(in)) (in.connected ? connected_samples : disconnect_markers) += 1;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    thread.stop();
    while (ring.try_pop(in)) (in.connected ? connected_samples : disconnect_markers) += 1;
    const InputThreadStats stats = thread.stats();
    CHECK(connected_samples == 800);
    CHECK(disconnect_markers == 1);
    CHECK(opens == 3);
    CHECK(stats.connects == 2);
    CHECK(stats.disconnects == 1);
    CHECK(stats.samples == 800);
}

TEST_CASE("input thread, hidraw: no pad at start is an error naming why", "[firmware_sim][input]") {
    InputThreadOptions options;
    options.backend = "hidraw";
    options.open_hid = [](const std::string&, OpenedHidPad&) { return Outcome::failure("no supported HID pad found"); };
    static InputRing ring;
    InputThread thread;
    const Outcome started = thread.start(ring, options);
    CHECK_FALSE(started.ok());
    CHECK(started.problem() == "no supported HID pad found");
}
