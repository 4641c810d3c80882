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
constexpr int kBatch = 64;                // evdev samples taken per poll
constexpr int kEvdevPollTimeoutMs = 20;   // an idle evdev runner wakes this often to see stop()
constexpr int kSdlPollTimeoutMs = 5;      // … and an idle SDL runner this often
constexpr int kHidInitTimeoutMs = 200;    // a pad's start-up dialogue waits this long for its replies
// A hidraw read returns as soon as a report comes; with none it waits this long
// (then looks at stop()): 1 ms woke an idle thread 1000 times a second for nothing.
constexpr int kHidReadTimeoutMs = 10;
constexpr int kHidReopenPollMs = 10;      // while a hidraw pad is unplugged, stop() is seen this soon

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
    if (Outcome chosen = choose_backend(); !chosen.ok()) return chosen;
    stop_requested_ = false;
    std::promise<Outcome> started;
    std::future<Outcome> result = started.get_future();
    thread_ = std::thread([this, &ring, &started] { run(ring, started); });
    Outcome outcome = result.get();
    if (!outcome.ok()) thread_.join();
    return outcome;
}

// Sets kind_ and description_ from options_.backend ("auto": probe the devices).
Outcome InputThread::choose_backend() {
    if (options_.backend == "auto") {
        const BackendChoice choice = probe_input_backend(options_.evdev_dir);
        kind_ = choice.kind;
        description_ = choice.reason;
        if (kind_ == BackendKind::none) return Outcome::failure(choice.reason);
        return Outcome::success();
    }
    const auto k = backend_from_name(options_.backend);
    if (!k) return Outcome::failure("--backend " + options_.backend + ": expected auto, hidraw, evdev or sdl");
    kind_ = *k;
    description_ = std::string(backend_name(kind_)) + ": chosen on the command line";
    return Outcome::success();
}

// The thread's body. Each runner opens its backend, reports through `started`
// exactly once (success once running, else why it could not open), then loops until stop().
void InputThread::run(InputRing& ring, std::promise<Outcome>& started) {
    switch (kind_) {
        case BackendKind::evdev: run_evdev(ring, started); break;
        case BackendKind::hidraw: run_hidraw(ring, started); break;
        case BackendKind::sdl: run_sdl(ring, started); break;
        case BackendKind::none: started.set_value(Outcome::failure("no backend")); return;
    }
    running_ = false;
}

void InputThread::push_calibrated(InputRingWriter<InputRing>& writer, const FamilyCalibration& cal, InputSample& s) {
    apply_calibration(cal, options_.raw, s);
    if (writer.push(to_timed_input(s))) samples_.fetch_add(1, std::memory_order_relaxed);
}

void InputThread::run_evdev(InputRing& ring, std::promise<Outcome>& started) {
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
    while (!stopping()) {
        const int n = backend.poll(batch, kEvdevPollTimeoutMs);
        for (int i = 0; i < n; ++i) push_calibrated(writer, cal, batch[static_cast<std::size_t>(i)]);
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
}

// The hidraw runner's pad: the transport it reads from (declared first, so it
// outlives the pad), the pad's format and calibration.
struct InputThread::HidSession {
    HidOpener open;
    OpenedHidPad opened;  // transport, format and node: declared before the pad that reads it
    std::optional<HidPad> pad;
    const FamilyCalibration* cal = nullptr;
    std::uint64_t rejected_by_earlier_pads = 0;
    InputSample sample;
};

void InputThread::run_hidraw(InputRing& ring, std::promise<Outcome>& started) {
    HidSession hid;
    hid.open = options_.open_hid ? options_.open_hid : HidOpener(open_first_hid_pad);
    if (Outcome first = hid.open(options_.device_path, hid.opened); !first.ok()) {
        started.set_value(std::move(first));
        return;
    }
    hid.pad.emplace(*hid.opened.transport, hid.opened.format);
    if (!hid.pad->initialise(kHidInitTimeoutMs)) {
        started.set_value(Outcome::failure(hid.opened.path + ": the pad did not accept its start-up reports"));
        return;
    }
    started.set_value(Outcome::success());
    running_ = true;
    connected_ = true;
    connects_ = 1;
    InputRingWriter<InputRing> writer(ring);
    hid.cal = &options_.config.family(family_of(hid.opened.format));
    while (!stopping()) {
        if (hid.pad) read_hid_pad(hid, writer);
        else reopen_hid_pad(hid);
    }
}

// One report (or none within kHidReadTimeoutMs). A disconnect is passed on to
// the simulation (the puppet idles until the pad is back) and drops the pad.
void InputThread::read_hid_pad(HidSession& hid, InputRingWriter<InputRing>& writer) {
    const HidPad::Result r = hid.pad->read(hid.sample, kHidReadTimeoutMs);
    if (r == HidPad::Result::sample) {
        hid.sample.t_ns = monotonic_now_ns();
        push_calibrated(writer, *hid.cal, hid.sample);
        ring_dropped_.store(writer.dropped(), std::memory_order_relaxed);
    } else if (r == HidPad::Result::rejected) {
        rejected_.store(hid.rejected_by_earlier_pads + hid.pad->counters().rejected(), std::memory_order_relaxed);
    } else if (r == HidPad::Result::disconnected) {
        writer.push_disconnect(monotonic_now_ns());
        connected_.store(false, std::memory_order_release);
        disconnects_.fetch_add(1);
        hid.rejected_by_earlier_pads += hid.pad->counters().rejected();
        hid.pad.reset();  // before the transport it reads from
        hid.opened.transport.reset();
    }
}

// Unplugged: look for the pad again every hid_reopen_interval_ms (hidraw gives
// no hotplug events; this is off the steady state).
void InputThread::reopen_hid_pad(HidSession& hid) {
    for (int waited = 0; waited < options_.hid_reopen_interval_ms && !stopping(); waited += kHidReopenPollMs)
        usleep(static_cast<useconds_t>(kHidReopenPollMs) * 1000u);
    if (!hid.open(options_.device_path, hid.opened).ok()) return;
    hid.pad.emplace(*hid.opened.transport, hid.opened.format);
    if (!hid.pad->initialise(kHidInitTimeoutMs)) {
        hid.pad.reset();
        hid.opened.transport.reset();
        return;
    }
    hid.cal = &options_.config.family(family_of(hid.opened.format));
    connected_.store(true, std::memory_order_release);
    connects_.fetch_add(1);
}

void InputThread::run_sdl(InputRing& ring, std::promise<Outcome>& started) {
    SdlBackend sdl;
    Outcome opened = sdl.start(options_.config.sdl_mapping_file);
    const bool ok = opened.ok();
    started.set_value(std::move(opened));
    if (!ok) return;
    running_ = true;
    InputRingWriter<InputRing> writer(ring);
    std::array<InputSample, 1> batch{};
    const FamilyCalibration& cal = options_.config.family(DeviceFamily::sdl);
    std::uint64_t disconnects_seen = 0;
    while (!stopping()) {
        if (sdl.poll(batch, kSdlPollTimeoutMs) == 1) push_calibrated(writer, cal, batch[0]);
        // A controller that went away is passed on to the simulation (the puppet
        // idles until a sample comes again), as the other backends do.
        if (sdl.disconnects() != disconnects_seen) {
            disconnects_seen = sdl.disconnects();
            writer.push_disconnect(monotonic_now_ns());
        }
        connected_.store(sdl.connected(), std::memory_order_release);
        connects_.store(sdl.connects(), std::memory_order_relaxed);
        disconnects_.store(sdl.disconnects(), std::memory_order_relaxed);
        ring_dropped_.store(writer.dropped(), std::memory_order_relaxed);
    }
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
