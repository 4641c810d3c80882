// `marionette input list|monitor|decode` and `marionette sim-pad`: the input
// backends and the simulated controller from the command line (docs/input.md).
#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <stdexcept>

#include "app/cli/cli.hpp"
#include "app/io/log.hpp"
#include "app/config/embedded.hpp"
#include "app/io/files.hpp"
#include "app/io/json.hpp"
#include "app/config/program_source.hpp"
#include "firmware_sim/sim_pad.hpp"
#include "input/calibration.hpp"
#include "input/evdev/evdev_backend.hpp"
#include "input/hid/hid_pad.hpp"
#include "input/hid/hidapi_transport.hpp"
#include "input/input_thread.hpp"
#include "input/sdl/sdl_backend.hpp"
#include "runtime/errors/import_error.hpp"

namespace marionette {

using namespace marionette::input;

namespace {

InputConfig load_input_config(const std::string& user_file) {
    const std::string_view text = embedded::find("config/input.toml");
    InputConfig config = apply_input_config_text(InputConfig{}, text, "config/input.toml");
    if (!user_file.empty()) config = apply_input_config_text(config, read_text_file(user_file), user_file);
    return config;
}

std::string sample_line(const InputSample& s, bool as_json) {
    if (as_json) {
        std::string line = fmt::format(
            "{{\"t_ns\":{},\"device\":{},\"lx\":{},\"ly\":{},\"rx\":{},\"ry\":{},\"lt\":{},\"rt\":{},\"buttons\":{}",
            s.t_ns, s.device_id, json::number(s.lx), json::number(s.ly), json::number(s.rx), json::number(s.ry),
            json::number(s.lt), json::number(s.rt), button_list_json(s.buttons));
        if (s.has_device_counter) line += fmt::format(",\"seq\":{}", s.device_counter);
        return line + "}";
    }
    std::string names;
    for (int i = 0; i < kButtonCount; ++i)
        if (s.buttons & (1u << i)) names += (names.empty() ? "" : ",") + std::string(kButtonNames[static_cast<std::size_t>(i)]);
    return fmt::format("t={:.6f}s L({:+.4f},{:+.4f}) R({:+.4f},{:+.4f}) LT {:.4f} RT {:.4f} [{}]", static_cast<double>(s.t_ns) * 1e-9,
                       s.lx, s.ly, s.rx, s.ry, s.lt, s.rt, names);
}

// ---- input decode ---------------------------------------------------------------

struct DecodeOptions {
    std::string format;
    std::string file;
    bool json = false;
    int rate_hz = 1000;
};

// Report length from the first byte (the report id), per format.
std::size_t report_length(HidFormat f, std::uint8_t first) {
    switch (f) {
        case HidFormat::ds4: return first == 0x11 ? 78 : 64;
        case HidFormat::dualsense: return first == 0x31 ? 78 : 64;
        case HidFormat::switchpro: return 64;
        case HidFormat::steamdeck: return 64;
    }
    return 64;
}

int decode_command(const DecodeOptions& o) {
    const auto format = hid_format_from_name(o.format);
    if (!format) throw ImportError("--format", 0, "'" + o.format + "': expected ds4, dualsense, switchpro or steamdeck");
    const std::vector<std::uint8_t> bytes = read_binary_file(o.file);
    ParseCounters counters;
    std::size_t at = 0;
    std::uint64_t index = 0;
    while (at < bytes.size()) {
        const std::size_t length = report_length(*format, bytes[at]);
        if (at + length > bytes.size()) {
            log_message(LogLevel::error, fmt::format("error: {}: at byte {}: {} bytes left, expected a whole {}-byte {} report", o.file, at,
                       bytes.size() - at, length, o.format));
            counters.count(ParseStatus::too_short);
            break;
        }
        InputSample s;
        const std::span<const std::uint8_t> report(bytes.data() + at, length);
        // Decoding is always raw: the device's own calibration (Switch Pro: the
        // defaults, as a file carries no SPI flash) and no deadzone or curve.
        const ParseStatus st = parse_hid_report(*format, report, switchpro::kDefaultCalibration, s);
        counters.count(st);
        if (st == ParseStatus::ok) {
            s.t_ns = static_cast<std::int64_t>(index) * 1'000'000'000 / o.rate_hz;
            fmt::print("{}\n", sample_line(s, o.json));
        } else if (st != ParseStatus::ignored) {
            log_message(LogLevel::warning, fmt::format("warning: {}: at byte {}: report {} rejected: {}", o.file, at, index, parse_status_name(st)));
        }
        at += length;
        ++index;
    }
    log_message(LogLevel::info, fmt::format("{}: {} reports decoded, {} rejected, {} ignored", o.file, counters.accepted, counters.rejected(),
               counters.ignored));
    if (counters.too_short > 0 || counters.accepted == 0) return 2;
    return 0;
}

// ---- input monitor --------------------------------------------------------------

struct MonitorOptions {
    std::string device;
    std::string backend = "auto";
    std::string input_config;
    std::string evdev_dir = "/dev/input";
    bool raw = false;
    bool json = false;
    long count = 0;          // 0: until interrupted
    double timeout_s = 0.0;  // 0: wait for ever
};

int monitor_command(const MonitorOptions& o) {
    const InputConfig config = load_input_config(o.input_config);
    std::string backend = o.backend;
    if (!o.device.empty() && backend == "auto") backend = o.device.find("hidraw") != std::string::npos ? "hidraw" : "evdev";
    if (backend == "auto") {
        const BackendChoice choice = probe_input_backend(o.evdev_dir);
        log_message(LogLevel::info, fmt::format("input: {}", choice.reason));
        if (choice.kind == BackendKind::none) return 1;
        backend = std::string(backend_name(choice.kind));
    }
    const auto kind = backend_from_name(backend);
    if (!kind) throw ImportError("--backend", 0, "'" + backend + "': expected auto, hidraw, evdev or sdl");

    long printed = 0;
    const auto start = std::chrono::steady_clock::now();
    auto last_sample = start;
    const auto timed_out = [&] {
        return o.timeout_s > 0 &&
               std::chrono::duration<double>(std::chrono::steady_clock::now() - last_sample).count() > o.timeout_s;
    };
    const auto emit = [&](InputSample& s, const FamilyCalibration& cal) {
        apply_calibration(cal, o.raw, s);
        fmt::print("{}\n", sample_line(s, o.json));
        std::fflush(stdout);
        ++printed;
        last_sample = std::chrono::steady_clock::now();
    };
    const auto done = [&] { return o.count > 0 && printed >= o.count; };

    if (*kind == BackendKind::evdev) {
        EvdevBackend evdev;
        const Outcome opened = o.device.empty() ? evdev.watch_directory(o.evdev_dir) : evdev.open_device(o.device);
        if (!opened.ok()) {
            log_message(LogLevel::error, fmt::format("error: {}", opened.problem()));
            return 1;
        }
        evdev.set_raw(o.raw);
        for (int i = 0; i < EvdevBackend::kMaxPads; ++i)
            if (const EvdevPad* p = evdev.pad(i))
                log_message(LogLevel::info, fmt::format("input: evdev: {} \"{}\" {:04x}:{:04x}", p->path(), p->name(), p->vendor_id(), p->product_id()));
        std::array<InputSample, 64> batch{};
        std::uint64_t disconnects = 0;
        while (!done() && !timed_out()) {
            const int n = evdev.poll(batch, 20);
            for (int i = 0; i < n && !done(); ++i) emit(batch[static_cast<std::size_t>(i)], config.family(DeviceFamily::evdev));
            if (evdev.disconnects() != disconnects) {
                disconnects = evdev.disconnects();
                log_message(LogLevel::info, fmt::format("input: device unplugged ({} connected)", evdev.connected()));
            }
        }
        if (evdev.syn_dropped() > 0) log_message(LogLevel::info, fmt::format("input: {} SYN_DROPPED resynchronised", evdev.syn_dropped()));
    } else if (*kind == BackendKind::hidraw) {
        std::string path = o.device;
        std::optional<HidFormat> format;
        for (const HidDeviceInfo& p : enumerate_hid_pads())
            if (path.empty() || p.path == path) {
                path = p.path;
                format = p.format;
                break;
            }
        if (!format) {
            log_message(LogLevel::error, fmt::format("error: {}", path.empty() ? "no supported HID pad found" : path + ": not a supported HID pad"));
            return 1;
        }
        auto transport = open_hidapi_transport(path);
        if (!transport) {
            log_message(LogLevel::error, fmt::format("error: {}: cannot open the hidraw node (permissions? see docs/input.md)", path));
            return 1;
        }
        HidPad pad(*transport, *format);
        pad.initialise(200);
        log_message(LogLevel::info, fmt::format("input: hidraw: {} ({})", path, hid_format_name(*format)));
        InputSample s;
        while (!done() && !timed_out()) {
            const HidPad::Result r = pad.read(s, 20);
            if (r == HidPad::Result::disconnected) {
                log_message(LogLevel::info, "input: device unplugged");
                break;
            }
            if (r == HidPad::Result::sample) {
                s.t_ns = monotonic_now_ns();
                emit(s, config.family(family_of(*format)));
            }
        }
        if (pad.counters().rejected() > 0) log_message(LogLevel::info, fmt::format("input: {} reports rejected", pad.counters().rejected()));
    } else {
        SdlBackend sdl;
        if (const Outcome started = sdl.start(config.sdl_mapping_file); !started.ok()) {
            log_message(LogLevel::error, fmt::format("error: {}", started.problem()));
            return 1;
        }
        log_message(LogLevel::info, fmt::format("input: sdl: {} joystick(s), {} mapping(s) loaded{}", sdl.joysticks(), sdl.mappings_loaded(),
                   sdl.connected() ? ", using \"" + sdl.controller_name() + "\"" : ""));
        std::array<InputSample, 1> batch{};
        while (!done() && !timed_out())
            if (sdl.poll(batch, 20) == 1) emit(batch[0], config.family(DeviceFamily::sdl));
    }
    if (o.count > 0 && printed < o.count) {
        log_message(LogLevel::info, fmt::format("input: {} of {} samples before the timeout", printed, o.count));
        return 1;
    }
    return 0;
}

// ---- input list ------------------------------------------------------------------

struct ListOptions {
    bool json = false;
    std::string evdev_dir = "/dev/input";
    double measure_s = 1.0;
};

int list_command(const ListOptions& o) {
    struct Row {
        std::string backend, path, name;
        std::uint16_t vendor, product;
        double rate_hz;
    };
    std::vector<Row> rows;
    {
        EvdevBackend evdev;
        if (evdev.watch_directory(o.evdev_dir).ok() && evdev.connected() > 0) {
            std::array<std::uint64_t, EvdevBackend::kMaxPads> frames{};
            std::array<InputSample, 64> batch{};
            const auto start = std::chrono::steady_clock::now();
            while (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < o.measure_s) {
                const int n = evdev.poll(batch, 10);
                for (int i = 0; i < n; ++i) ++frames[batch[static_cast<std::size_t>(i)].device_id];
            }
            for (int i = 0; i < EvdevBackend::kMaxPads; ++i)
                if (const EvdevPad* p = evdev.pad(i))
                    rows.push_back({"evdev", p->path(), p->name(), p->vendor_id(), p->product_id(),
                                    static_cast<double>(frames[static_cast<std::size_t>(i)]) / o.measure_s});
        }
    }
    for (const HidDeviceInfo& h : enumerate_hid_pads()) {
        double rate = -1.0;  // not measurable (cannot open)
        if (auto transport = open_hidapi_transport(h.path)) {
            HidPad pad(*transport, h.format);
            pad.initialise(200);
            InputSample s;
            std::uint64_t n = 0;
            const auto start = std::chrono::steady_clock::now();
            while (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < o.measure_s) {
                const HidPad::Result r = pad.read(s, 10);
                if (r == HidPad::Result::disconnected) break;
                if (r == HidPad::Result::sample) ++n;
            }
            rate = static_cast<double>(n) / o.measure_s;
        }
        rows.push_back({"hidraw", h.path, h.name, h.vendor_id, h.product_id, rate});
    }
    if (o.json) {
        std::string out = "{\"devices\":[";
        for (std::size_t i = 0; i < rows.size(); ++i) {
            const Row& r = rows[i];
            out += fmt::format("{}{{\"backend\":{},\"path\":{},\"name\":{},\"vendor_id\":\"{:04x}\",\"product_id\":\"{:04x}\","
                               "\"report_rate_hz\":{}}}",
                               i ? "," : "", json::quote(r.backend), json::quote(r.path), json::quote(r.name), r.vendor,
                               r.product, r.rate_hz < 0 ? "null" : json::number(r.rate_hz));
        }
        fmt::print("{}]}}\n", out);
    } else if (rows.empty()) {
        fmt::print("no gamepads found (evdev under {}, hidraw)\n", o.evdev_dir);
    } else {
        for (const Row& r : rows)
            fmt::print("{:<7} {:<22} {:04x}:{:04x} {:>7} Hz  {}\n", r.backend, r.path, r.vendor, r.product,
                       r.rate_hz < 0 ? std::string("?") : fmt::format("{:.0f}", r.rate_hz), r.name);
    }
    return 0;
}

// ---- sim-pad ----------------------------------------------------------------------

struct SimPadCommandOptions {
    std::string format;
    int rate_hz = 1000;
    std::string program;
    std::string faults;
    std::string out;
    std::string pad = "xbox";
    bool bluetooth = false;
    bool json = false;
};

int sim_pad_command(const SimPadCommandOptions& o) {
    firmware_sim::SimPadOptions options;
    const bool evemu = o.format == "evemu";
    if (!evemu) {
        options.hid_format = hid_format_from_name(o.format);
        if (!options.hid_format)
            throw ImportError("--format", 0, "'" + o.format + "': expected ds4, dualsense, switchpro, steamdeck or evemu");
    }
    const auto model = firmware_sim::evdev_pad_model_from_name(o.pad);
    if (!model) throw ImportError("--pad", 0, "'" + o.pad + "': expected xbox or dualsense");
    if (o.rate_hz < firmware_sim::kMinRateHz || o.rate_hz > firmware_sim::kMaxRateHz)
        throw ImportError("--rate", 0, fmt::format("{} Hz: expected {} to {} Hz", o.rate_hz, firmware_sim::kMinRateHz,
                                                   firmware_sim::kMaxRateHz));
    if (o.bluetooth && options.hid_format != HidFormat::ds4 && options.hid_format != HidFormat::dualsense)
        throw ImportError("--bluetooth", 0, "only ds4 and dualsense have Bluetooth reports here");
    options.rate_hz = o.rate_hz;
    options.bluetooth = o.bluetooth;
    options.faults = firmware_sim::parse_faults(o.faults);
    // A file carries no SPI flash, so a decoder can only assume the documented
    // default calibration: write with that one, and `input decode` is exact.
    options.switch_calibration = switchpro::kDefaultCalibration;
    const StickProgram program = load_program(o.program);
    const firmware_sim::SimStream stream = firmware_sim::simulate_pad(program, options);
    std::size_t bytes = 0;
    if (evemu) {
        const std::string text = firmware_sim::write_evemu_stream(stream, firmware_sim::evdev_pad_description(*model));
        write_text_file(o.out, text);
        bytes = text.size();
    } else {
        const std::vector<std::uint8_t> data = firmware_sim::concatenate_reports(stream);
        std::FILE* f = std::fopen(o.out.c_str(), "wb");
        if (!f || std::fwrite(data.data(), 1, data.size(), f) != data.size()) {
            if (f) std::fclose(f);
            throw std::runtime_error(o.out + ": cannot write");
        }
        std::fclose(f);
        bytes = data.size();
    }
    const auto& st = stream.stats;
    const double duration = program.duration_s();
    if (o.json) {
        fmt::print("{{\"out\":{},\"format\":{},\"rate_hz\":{},\"duration_s\":{},\"reports\":{},\"bytes\":{},\"dropped\":{},"
                   "\"duplicated\":{},\"corrupted\":{},\"unplugs\":{},\"syn_dropped\":{},\"faults\":{}}}\n",
                   json::quote(o.out), json::quote(o.format), o.rate_hz, json::number(duration), st.reports, bytes,
                   st.dropped, st.duplicated, st.corrupted, st.unplugs, st.syn_dropped,
                   json::quote(firmware_sim::describe_faults(options.faults)));
    } else {
        fmt::print("wrote {} {} reports ({} bytes, {:.3f} s at {} Hz) to {}; dropped {}, duplicated {}, corrupted {}, "
                   "unplugs {}, SYN_DROPPED {}\n",
                   st.reports, o.format, bytes, duration, o.rate_hz, o.out, st.dropped, st.duplicated, st.corrupted,
                   st.unplugs, st.syn_dropped);
    }
    return 0;
}

}  // namespace

void register_input_commands(CLI::App& app, int& exit_code) {
    CLI::App* input = app.add_subcommand("input", "Gamepads: list, monitor, decode raw HID reports");
    input->require_subcommand(1);

    auto list = std::make_shared<ListOptions>();
    CLI::App* list_cmd = input->add_subcommand("list", "Gamepads found, with backend, ids and report rate over 1 s");
    list_cmd->add_flag("--json", list->json, "print JSON");
    list_cmd->add_option("--evdev-dir", list->evdev_dir, "directory of evdev nodes");
    on_parsed(list_cmd, exit_code, [list] { return list_command(*list); });

    auto mon = std::make_shared<MonitorOptions>();
    CLI::App* mon_cmd = input->add_subcommand("monitor", "Print one sample per evdev frame / HID report");
    auto* device_opt = mon_cmd->add_option("--device", mon->device, "an evdev node (/dev/input/eventN) or hidraw node");
    mon_cmd->add_option("--backend", mon->backend, "auto|evdev|hidraw|sdl")
        ->check(CLI::IsMember({"auto", "evdev", "hidraw", "hid", "sdl"}))
        ->excludes(device_opt);
    mon_cmd->add_flag("--raw", mon->raw, "skip deadzone and response curve");
    mon_cmd->add_option("--count", mon->count, "exit after N samples")->check(CLI::Range(1L, 1L << 40));
    mon_cmd->add_flag("--json", mon->json, "one JSON object per sample");
    mon_cmd->add_option("--input-config", mon->input_config, "calibration TOML overriding config/input.toml")
        ->check(CLI::ExistingFile);
    mon_cmd->add_option("--timeout", mon->timeout_s, "give up after this many seconds without a sample")
        ->check(CLI::Range(0.0, 86400.0));
    mon_cmd->add_option("--evdev-dir", mon->evdev_dir, "directory of evdev nodes");
    on_parsed(mon_cmd, exit_code, [mon] { return monitor_command(*mon); });

    auto dec = std::make_shared<DecodeOptions>();
    CLI::App* dec_cmd = input->add_subcommand("decode", "Decode a file of raw HID reports (as --raw)");
    dec_cmd->add_option("--format", dec->format, "ds4|dualsense|switchpro|steamdeck")->required();
    dec_cmd->add_option("file", dec->file, "concatenated reports, each as hidraw's read() returns it")->required();
    dec_cmd->add_flag("--json", dec->json, "one JSON object per report");
    dec_cmd->add_option("--rate", dec->rate_hz, "report rate for t_ns (reports carry no host time)")
        ->check(CLI::Range(1, 100000));
    on_parsed(dec_cmd, exit_code, [dec] { return decode_command(*dec); });

    auto sim = std::make_shared<SimPadCommandOptions>();
    CLI::App* sim_cmd = app.add_subcommand("sim-pad", "Simulated controller firmware: reports or evemu events from a stick program");
    sim_cmd->add_option("--format", sim->format, "ds4|dualsense|switchpro|steamdeck|evemu")->required();
    sim_cmd->add_option("--rate", sim->rate_hz, "reports per second (125 to 8000)");
    sim_cmd->add_option("--program", sim->program, "stick program file (or builtin:NAME)")->required();
    sim_cmd->add_option("--faults", sim->faults, "noise=SD,drift=D,quant=BITS,jitter=T,drop=P,dup=P,corrupt=P,unplug=AT+FOR,syn_dropped=AT,seed=N");
    sim_cmd->add_option("--out", sim->out, "file to write")->required();
    sim_cmd->add_option("--pad", sim->pad, "evemu: xbox|dualsense (which evdev pad the events are for)");
    sim_cmd->add_flag("--bluetooth", sim->bluetooth, "ds4/dualsense: Bluetooth reports (0x11/0x31 with CRC)");
    sim_cmd->add_flag("--json", sim->json, "print a JSON summary");
    on_parsed(sim_cmd, exit_code, [sim] { return sim_pad_command(*sim); });
}

}  // namespace marionette
