#include "firmware_sim/sim_pad.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace marionette::firmware_sim {

using input::HidFormat;

namespace {

constexpr std::uint16_t kEvSyn = 0, kEvKey = 1, kEvAbs = 3;
constexpr std::uint16_t kSynReport = 0, kSynDropped = 3;

PadState state_of(const TickInput& t) {
    PadState s;
    s.lx = t.left_x / 32767.0;
    s.ly = t.left_y / 32767.0;
    s.rx = t.right_x / 32767.0;
    s.ry = t.right_y / 32767.0;
    s.lt = t.left_trigger / 65535.0;
    s.rt = t.right_trigger / 65535.0;
    s.buttons = t.buttons;
    return s;
}

double quantise(double v, int bits) {
    const double levels = std::ldexp(1.0, bits - 1) - 1.0;
    return std::round(v * levels) / levels;
}

void garble(Report& r, HidFormat format, bool bluetooth) {
    // Same length as the real report (a file of reports keeps its framing), but
    // something no parser may accept.
    if (format == HidFormat::steamdeck) r.bytes[0] = 0xEE;       // header version
    else if (bluetooth) r.bytes[r.size / 2] ^= 0x5A;             // CRC no longer matches
    else r.bytes[0] = 0xEE;                                       // no such report id
}

}  // namespace

SimStream simulate_pad(const StickProgram& program, const SimPadOptions& o) {
    if (o.rate_hz < kMinRateHz || o.rate_hz > kMaxRateHz)
        throw std::invalid_argument(fmt::format("report rate {} Hz is outside [{}, {}] Hz", o.rate_hz, kMinRateHz, kMaxRateHz));
    const FaultSpec& f = o.faults;
    SimRandom rng(f.seed);
    const std::vector<TickInput> ticks = render_stick_program(program, o.rate_hz);
    SimStream out;
    out.rate_hz = o.rate_hz;
    out.frames.reserve(ticks.size() + 8);
    const double period_s = 1.0 / o.rate_hz;
    std::vector<double> syn_dropped = f.syn_dropped_at_s;
    std::sort(syn_dropped.begin(), syn_dropped.end());
    std::size_t next_syn_dropped = 0;
    bool unplugged = false;
    std::int64_t last_t = 0;
    ReportClock clock;
    const std::size_t n = ticks.size();
    for (std::size_t k = 0; k < n; ++k) {
        const double nominal_s = static_cast<double>(k) * period_s;
        // Every random draw happens for every report, so one fault's setting never
        // shifts another fault's sequence.
        const double jitter = (rng.uniform() * 2.0 - 1.0) * f.jitter_s;
        const double draw_drop = rng.uniform(), draw_dup = rng.uniform(), draw_corrupt = rng.uniform();
        const double noise[4] = {rng.gaussian(), rng.gaussian(), rng.gaussian(), rng.gaussian()};

        while (next_syn_dropped < syn_dropped.size() && syn_dropped[next_syn_dropped] <= nominal_s) {
            SimFrame d;
            d.kind = SimFrame::Kind::syn_dropped;
            d.t_ns = std::max(last_t, static_cast<std::int64_t>(std::llround(syn_dropped[next_syn_dropped] * 1e9)));
            out.frames.push_back(d);
            ++out.stats.syn_dropped;
            ++next_syn_dropped;
        }
        if (f.unplug_at_s >= 0) {
            const bool gone = nominal_s >= f.unplug_at_s && nominal_s < f.unplug_at_s + f.unplug_for_s;
            if (gone != unplugged) {
                SimFrame u;
                u.kind = gone ? SimFrame::Kind::unplug : SimFrame::Kind::replug;
                u.t_ns = std::max(last_t, static_cast<std::int64_t>(std::llround(nominal_s * 1e9)));
                out.frames.push_back(u);
                if (gone) ++out.stats.unplugs;
                unplugged = gone;
                if (!gone) clock = ReportClock{};  // a replugged pad starts counting again
            }
            if (gone) continue;
        }

        PadState s = state_of(ticks[k]);
        const double drift = f.drift * (n > 1 ? static_cast<double>(k) / static_cast<double>(n - 1) : 0.0);
        double* axes[4] = {&s.lx, &s.ly, &s.rx, &s.ry};
        for (int a = 0; a < 4; ++a) {
            double v = *axes[a] + drift + f.noise * noise[a];
            v = std::clamp(v, -1.0, 1.0);
            if (f.quant_bits > 0) v = quantise(v, f.quant_bits);
            *axes[a] = v;
        }
        clock.device_time_us = static_cast<std::uint64_t>(std::llround(nominal_s * 1e6));
        std::int64_t t_ns = static_cast<std::int64_t>(std::llround((nominal_s + jitter) * 1e9));
        t_ns = std::max(t_ns, last_t);  // reports leave the device in order
        last_t = t_ns;

        if (draw_drop < f.drop) {
            ++out.stats.dropped;
            ++clock.counter;  // the firmware counted it; the host never saw it
            continue;
        }
        SimFrame frame;
        frame.t_ns = t_ns;
        frame.state = s;
        if (o.hid_format) {
            frame.report = encode_report(*o.hid_format, s, clock, o.bluetooth, o.switch_calibration);
            if (draw_corrupt < f.corrupt) {
                garble(frame.report, *o.hid_format, o.bluetooth);
                frame.corrupted = true;
                ++out.stats.corrupted;
            }
        }
        out.frames.push_back(frame);
        ++out.stats.reports;
        if (draw_dup < f.duplicate) {
            SimFrame again = frame;
            again.duplicate = true;
            out.frames.push_back(again);
            ++out.stats.reports;
            ++out.stats.duplicated;
        }
        ++clock.counter;
    }
    if (unplugged) {  // the program ended while unplugged: the pad comes back at the end
        SimFrame u;
        u.kind = SimFrame::Kind::replug;
        u.t_ns = last_t;
        out.frames.push_back(u);
    }
    return out;
}

std::vector<std::uint8_t> concatenate_reports(const SimStream& stream) {
    std::vector<std::uint8_t> out;
    for (const SimFrame& f : stream.frames)
        if (f.kind == SimFrame::Kind::report) out.insert(out.end(), f.report.view().begin(), f.report.view().end());
    return out;
}

std::optional<EvdevPadModel> evdev_pad_model_from_name(const std::string& name) {
    if (name == "xbox") return EvdevPadModel::xbox;
    if (name == "dualsense") return EvdevPadModel::dualsense;
    return std::nullopt;
}

const EvdevPadDescription& evdev_pad_description(EvdevPadModel model) {
    // Codes from linux/input-event-codes.h; positions per the kernel's
    // Documentation/input/gamepad.rst (BTN_WEST is the left face button).
    static const EvdevPadDescription kXbox = {
        "Microsoft X-Box 360 pad", 0x0003, 0x045e, 0x028e, 0x0114,
        {0x00, -32768, 32767, 16, 128}, {0x01, -32768, 32767, 16, 128},
        {0x03, -32768, 32767, 16, 128}, {0x04, -32768, 32767, 16, 128},
        {0x02, 0, 255, 0, 0}, {0x05, 0, 255, 0, 0},
        {0x10, -1, 1, 0, 0}, {0x11, -1, 1, 0, 0},
        {0x130, 0x131, 0x134, 0x133, 0x136, 0x137, 0x13a, 0x13b, 0x13c, 0x13d, 0x13e}, 0, 0};
    static const EvdevPadDescription kDualSense = {
        "Sony Interactive Entertainment DualSense Wireless Controller", 0x0003, 0x054c, 0x0ce6, 0x8111,
        {0x00, 0, 255, 0, 0}, {0x01, 0, 255, 0, 0},
        {0x03, 0, 255, 0, 0}, {0x04, 0, 255, 0, 0},
        {0x02, 0, 255, 0, 0}, {0x05, 0, 255, 0, 0},
        {0x10, -1, 1, 0, 0}, {0x11, -1, 1, 0, 0},
        {0x130, 0x131, 0x134, 0x133, 0x136, 0x137, 0x13a, 0x13b, 0x13c, 0x13d, 0x13e}, 0x138, 0x139};
    return model == EvdevPadModel::xbox ? kXbox : kDualSense;
}

namespace {
struct EvdevValues {
    std::array<std::int32_t, 8> axes{};  // lx ly rx ry lt rt hatx haty, raw
    std::array<bool, 13> keys{};         // the 11 keys, then tl2 tr2
};
EvdevValues raw_values(const PadState& s, const EvdevPadDescription& p) {
    EvdevValues v;
    v.axes[0] = encode_centred(s.lx, p.left_x.min, p.left_x.max);
    v.axes[1] = encode_centred(-s.ly, p.left_y.min, p.left_y.max);  // evdev y grows downwards
    v.axes[2] = encode_centred(s.rx, p.right_x.min, p.right_x.max);
    v.axes[3] = encode_centred(-s.ry, p.right_y.min, p.right_y.max);
    v.axes[4] = encode_trigger(s.lt, p.left_trigger.min, p.left_trigger.max);
    v.axes[5] = encode_trigger(s.rt, p.right_trigger.min, p.right_trigger.max);
    const auto has = [&](Button b) { return (s.buttons & button_bit(b)) != 0; };
    v.axes[6] = (has(Button::dpad_right) ? 1 : 0) - (has(Button::dpad_left) ? 1 : 0);
    v.axes[7] = (has(Button::dpad_down) ? 1 : 0) - (has(Button::dpad_up) ? 1 : 0);
    static constexpr Button kOrder[11] = {Button::south, Button::east, Button::west, Button::north,
                                          Button::left_shoulder, Button::right_shoulder, Button::back, Button::start,
                                          Button::guide, Button::left_stick, Button::right_stick};
    for (int i = 0; i < 11; ++i) v.keys[static_cast<std::size_t>(i)] = has(kOrder[i]);
    v.keys[11] = s.lt > 0.0;
    v.keys[12] = s.rt > 0.0;
    return v;
}
EvdevValues rest_values(const EvdevPadDescription& p) { return raw_values(PadState{}, p); }
}  // namespace

std::string write_evemu_stream(const SimStream& stream, const EvdevPadDescription& p) {
    std::string out;
    out += "# EVEMU 1.3\n# written by marionette firmware_sim\n";
    out += fmt::format("N: {}\nI: {:04x} {:04x} {:04x} {:04x}\n", p.name, p.bustype, p.vendor, p.product, p.version);
    const EvdevAxis* axes[8] = {&p.left_x, &p.left_y, &p.right_x, &p.right_y, &p.left_trigger, &p.right_trigger, &p.hat_x, &p.hat_y};
    for (const EvdevAxis* a : axes) out += fmt::format("A: {:02x} {} {} {} {} 0\n", a->code, a->min, a->max, a->fuzz, a->flat);
    const auto event = [&](std::int64_t t_ns, std::uint16_t type, std::uint16_t code, std::int32_t value) {
        const std::int64_t us = t_ns / 1000;
        out += fmt::format("E: {}.{:06d} {:04x} {:04x} {}\n", us / 1000000, us % 1000000, type, code, value);
    };
    EvdevValues last = rest_values(p);
    bool resend_all = false;
    for (const SimFrame& f : stream.frames) {
        if (f.kind == SimFrame::Kind::syn_dropped) {
            // The overflow: SYN_DROPPED, then the SYN_REPORT that ends the lost
            // packet (the client discards up to it), then full state at the next change.
            event(f.t_ns, kEvSyn, kSynDropped, 0);
            event(f.t_ns, kEvSyn, kSynReport, 0);
            resend_all = true;
            continue;
        }
        if (f.kind != SimFrame::Kind::report) continue;  // unplug cannot be expressed in an event file
        const EvdevValues v = raw_values(f.state, p);
        // After SYN_DROPPED the full state goes with the next frame that changes
        // something, never straight after it: a reader's resync may drain what is
        // already queued, and a frame there would be lost or not by timing alone.
        if (resend_all && v.axes == last.axes && v.keys == last.keys) continue;
        bool any = false;
        for (std::size_t i = 0; i < 8; ++i)
            if (resend_all || v.axes[i] != last.axes[i]) {
                event(f.t_ns, kEvAbs, axes[i]->code, v.axes[i]);
                any = true;
            }
        for (std::size_t i = 0; i < 13; ++i) {
            const std::uint16_t code = i < 11 ? p.keys[i] : (i == 11 ? p.key_tl2 : p.key_tr2);
            if (code == 0) continue;
            if (resend_all || v.keys[i] != last.keys[i]) {
                event(f.t_ns, kEvKey, code, v.keys[i] ? 1 : 0);
                any = true;
            }
        }
        if (any) event(f.t_ns, kEvSyn, kSynReport, 0);
        last = v;
        resend_all = false;
    }
    return out;
}

}  // namespace marionette::firmware_sim
