#include "input/input_thread.hpp"

#include <unistd.h>

#include <array>
#include <future>
#include <memory>
#include <optional>

#include "input/evdev/evdev_backend.hpp"
#include "input/hid/hid_pad.hpp"
#include "input/hid/hidapi_transport.hpp"
#include "input/sdl/sdl_backend.hpp"

namespace marionette::input {

namespace {
constexpr int kBatch = 64;

DeviceFamily family_of(HidFormat f) {
    switch (f) {
        case HidFormat::ds4: return DeviceFamily::ds4;
        case HidFormat::dualsense: return DeviceFamily::dualsense;
        case HidFormat::switchpro: return DeviceFamily::switchpro;
        case HidFormat::steamdeck: return DeviceFamily::steamdeck;
    }
    return DeviceFamily::evdev;
}
}  // namespace

Outcome open_first_hid_pad(const std::string& wanted_path, OpenedHidPad& opened) {
    for (const HidDeviceInfo& p : enumerate_hid_pads())
        if (wanted_path.empty() || p.path == wanted_path) {
            opened.transport = open_hidapi_transport(p.path);
            if (!opened.transport)
                return Outcome::failure(p.path + ": cannot open the hidraw node (permissions? see docs/input.md)");
            opened.path = p.path;
            opened.format = p.format;
            return Outcome::success();
        }
    return Outcome::failure(wanted_path.empty() ? "no supported HID pad found" : wanted_path + ": not a supported HID pad");
}

BackendChoice probe_input_backend(const std::string& evdev_dir) {
    AutoSelectInputs found;
    for (const HidDeviceInfo& h : enumerate_hid_pads())
        found.hid.push_back({h.vendor_id, h.product_id, h.interface_number, access(h.path.c_str(), R_OK | W_OK) == 0});
    for (const EvdevDeviceInfo& e : enumerate_evdev_gamepads(evdev_dir))
        found.evdev.push_back({e.path, e.vendor_id, e.product_id});
    if (found.hid.empty() && found.evdev.empty()) {
        SdlBackend sdl;
        found.sdl_available = sdl.start("").ok();
        found.sdl_joysticks = sdl.joysticks();
    }
    return choose_input_backend(found);
}

Outcome InputThread::start(InputRing& ring, const InputThreadOptions& options) {
    stop();
    options_ = options;
    if (options.backend == "auto") {
        const BackendChoice choice = probe_input_backend(options.evdev_dir);
        kind_ = choice.kind;
        description_ = choice.reason;
        if (kind_ == BackendKind::none) return Outcome::failure(choice.reason);
    } else {
        const auto k = backend_from_name(options.backend);
        if (!k) return Outcome::failure("--backend " + options.backend + ": expected auto, hidraw, evdev or sdl");
        kind_ = *k;
        description_ = std::string(backend_name(kind_)) + ": chosen on the command line";
    }
    stop_requested_ = false;
    std::promise<Outcome> started;
    std::future<Outcome> result = started.get_future();
    thread_ = std::thread([this, &ring, &started] {
        // Each runner opens its backend, reports success or failure through
        // `started` (exactly once), then loops until stop().
        switch (kind_) {
            case BackendKind::evdev: {
                EvdevBackend backend;
                Outcome opened = options_.device_path.empty() ? backend.watch_directory(options_.evdev_dir)
                                                              : backend.open_device(options_.device_path);
                const bool ok = opened.ok();
                started.set_value(std::move(opened));
                if (!ok) return;
                running_ = true;
                backend.set_raw(options_.raw);
                InputRingWriter<InputRing> writer(ring);
                std::array<InputSample, kBatch> batch{};
                const FamilyCalibration& cal = options_.config.family(DeviceFamily::evdev);
                bool was_connected = backend.connected() > 0;
                while (!stop_requested_.load(std::memory_order_relaxed)) {
                    const int n = backend.poll(batch, 20);
                    for (int i = 0; i < n; ++i) {
                        InputSample& s = batch[static_cast<std::size_t>(i)];
                        apply_calibration(cal, options_.raw, s);
                        if (writer.push(to_timed_input(s))) samples_.fetch_add(1, std::memory_order_relaxed);
                    }
                    const bool now_connected = backend.connected() > 0;
                    // The last pad left: tell the simulation (the puppet idles).
                    if (was_connected && !now_connected) writer.push_disconnect(monotonic_now_ns());
                    writer.flush_pending();
                    was_connected = now_connected;
                    connected_.store(now_connected, std::memory_order_release);
                    connects_.store(backend.connects(), std::memory_order_relaxed);
                    disconnects_.store(backend.disconnects(), std::memory_order_relaxed);
                    syn_dropped_.store(backend.syn_dropped(), std::memory_order_relaxed);
                    ring_dropped_.store(writer.dropped(), std::memory_order_relaxed);
                }
                break;
            }
            case BackendKind::hidraw: {
                const HidOpener& open = options_.open_hid ? options_.open_hid : open_first_hid_pad;
                OpenedHidPad opened;
                if (Outcome first = open(options_.device_path, opened); !first.ok()) {
                    started.set_value(std::move(first));
                    return;
                }
                std::optional<HidPad> pad;
                pad.emplace(*opened.transport, opened.format);
                if (!pad->initialise(200)) {
                    started.set_value(Outcome::failure(opened.path + ": the pad did not accept its start-up reports"));
                    return;
                }
                started.set_value(Outcome::success());
                running_ = true;
                connected_ = true;
                connects_ = 1;
                InputRingWriter<InputRing> writer(ring);
                const FamilyCalibration* cal = &options_.config.family(family_of(opened.format));
                std::uint64_t rejected_by_earlier_pads = 0;
                InputSample s;
                while (!stop_requested_.load(std::memory_order_relaxed)) {
                    if (!pad) {
                        // Unplugged: look for the pad again now and then (hidraw
                        // gives no hotplug events; this is off the steady state).
                        for (int waited = 0; waited < options_.hid_reopen_interval_ms &&
                                             !stop_requested_.load(std::memory_order_relaxed);
                             waited += 10)
                            usleep(10'000);
                        if (!open(options_.device_path, opened).ok()) continue;
                        pad.emplace(*opened.transport, opened.format);
                        if (!pad->initialise(200)) {
                            pad.reset();
                            opened.transport.reset();
                            continue;
                        }
                        cal = &options_.config.family(family_of(opened.format));
                        connected_.store(true, std::memory_order_release);
                        connects_.fetch_add(1);
                        continue;
                    }
                    const HidPad::Result r = pad->read(s, 1);
                    if (r == HidPad::Result::sample) {
                        s.t_ns = monotonic_now_ns();
                        apply_calibration(*cal, options_.raw, s);
                        if (writer.push(to_timed_input(s))) samples_.fetch_add(1, std::memory_order_relaxed);
                        ring_dropped_.store(writer.dropped(), std::memory_order_relaxed);
                    } else if (r == HidPad::Result::rejected) {
                        rejected_.store(rejected_by_earlier_pads + pad->counters().rejected(),
                                        std::memory_order_relaxed);
                    } else if (r == HidPad::Result::disconnected) {
                        // The simulation sees the disconnect (the puppet idles) until
                        // the pad is back.
                        writer.push_disconnect(monotonic_now_ns());
                        connected_.store(false, std::memory_order_release);
                        disconnects_.fetch_add(1);
                        rejected_by_earlier_pads += pad->counters().rejected();
                        pad.reset();  // before the transport it reads from
                        opened.transport.reset();
                    }
                }
                break;
            }
            case BackendKind::sdl: {
                SdlBackend sdl;
                Outcome opened = sdl.start(options_.config.sdl_mapping_file);
                const bool ok = opened.ok();
                started.set_value(std::move(opened));
                if (!ok) return;
                running_ = true;
                InputRingWriter<InputRing> writer(ring);
                std::array<InputSample, 1> batch{};
                const FamilyCalibration& cal = options_.config.family(DeviceFamily::sdl);
                while (!stop_requested_.load(std::memory_order_relaxed)) {
                    if (sdl.poll(batch, 5) == 1) {
                        apply_calibration(cal, options_.raw, batch[0]);
                        if (writer.push(to_timed_input(batch[0]))) samples_.fetch_add(1, std::memory_order_relaxed);
                    }
                    connected_.store(sdl.connected(), std::memory_order_release);
                    connects_.store(sdl.connects(), std::memory_order_relaxed);
                    disconnects_.store(sdl.disconnects(), std::memory_order_relaxed);
                    ring_dropped_.store(writer.dropped(), std::memory_order_relaxed);
                }
                break;
            }
            case BackendKind::none: started.set_value(Outcome::failure("no backend")); return;
        }
        running_ = false;
    });
    Outcome opened = result.get();
    if (!opened.ok()) thread_.join();
    return opened;
}

void InputThread::stop() {
    stop_requested_ = true;
    if (thread_.joinable()) thread_.join();
    running_ = false;
    connected_ = false;
}

InputThreadStats InputThread::stats() const {
    InputThreadStats s;
    s.samples = samples_.load();
    s.ring_dropped = ring_dropped_.load();
    s.rejected_reports = rejected_.load();
    s.connects = connects_.load();
    s.disconnects = disconnects_.load();
    s.syn_dropped = syn_dropped_.load();
    return s;
}

}  // namespace marionette::input
