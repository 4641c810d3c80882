#pragma once
// The input thread: opens the chosen backend, then loops waking on each report
// (evdev/SDL: epoll/SDL's queue; hidraw: a read with a 1 ms timeout, so at
// least 1 kHz), stamps each sample with CLOCK_MONOTONIC as it is read (or the
// kernel's monotonic event time, which is earlier), calibrates it, and pushes it
// into the pipeline's SPSC ring through InputRingWriter (a full ring drops the
// newest sample and folds its buttons into the next). After start() returns it
// allocates only when a pad is plugged back in.
//
//   InputRing ring;
//   InputThread input;
//   if (!input.start(ring, options).ok()) ...;    // backend chosen and opened
//   ... simulation thread: TickInputAssembler::assemble(ring, t, stats) ...
//   input.stop();
#include <atomic>
#include <cstdint>
#include <functional>
#include <future>
#include <memory>
#include <string>
#include <thread>

#include "input/auto_select.hpp"
#include "input/calibration.hpp"
#include "input/hid/hid_report.hpp"
#include "input/hid/hid_transport.hpp"
#include "runtime/errors/outcome.hpp"
#include "runtime/handoff/spsc_ring.hpp"
#include "runtime/handoff/tick_input_assembler.hpp"

namespace marionette::input {

// 4096 samples: 0.5 s at 8 kHz, far more than one tick's worth.
using InputRing = SpscRing<TimedInput, 4096>;

// A pad the hidraw backend opened: the transport it reads, its report format
// and its node.
struct OpenedHidPad {
    std::unique_ptr<HidTransport> transport;
    HidFormat format = HidFormat::ds4;
    std::string path;
};

// How the hidraw backend reaches a pad: opens `wanted_path` (empty: the first
// supported pad) into `opened`, or fails saying why.
using HidOpener = std::function<Outcome(const std::string& wanted_path, OpenedHidPad& opened)>;
// The default opener: hidapi enumeration and hidraw.
Outcome open_first_hid_pad(const std::string& wanted_path, OpenedHidPad& opened);

struct InputThreadOptions {
    std::string backend = "auto";         // auto, hidraw, evdev, sdl
    std::string device_path;              // evdev node or hidraw node; empty: the first found
    std::string evdev_dir = "/dev/input";
    bool raw = false;                     // skip deadzone and response curve
    InputConfig config;                   // calibration per family, SDL mapping file
    HidOpener open_hid;                   // empty: open_first_hid_pad (tests hand in firmware_sim)
    int hid_reopen_interval_ms = 250;     // how often an unplugged hidraw pad is looked for
};

struct InputThreadStats {
    std::uint64_t samples = 0;           // pushed into the ring
    std::uint64_t ring_dropped = 0;      // ring full
    std::uint64_t rejected_reports = 0;  // HID reports the parser refused
    std::uint64_t connects = 0;
    std::uint64_t disconnects = 0;
    std::uint64_t syn_dropped = 0;
};

class InputThread {
public:
    InputThread() = default;
    ~InputThread() { stop(); }
    InputThread(const InputThread&) = delete;
    InputThread& operator=(const InputThread&) = delete;

    // Chooses (for "auto") and opens the backend on the new thread, and returns
    // once it is running (ok) or has failed (saying why).
    Outcome start(InputRing& ring, const InputThreadOptions& options);
    void stop();

    bool running() const { return running_.load(std::memory_order_acquire); }
    bool device_connected() const { return connected_.load(std::memory_order_acquire); }
    // Which backend and why ("hidraw: Sony DualSense 054c:0ce6"); set by start().
    const std::string& backend_description() const { return description_; }
    InputThreadStats stats() const;
    // The running thread, so the pipeline can name it and apply the [realtime]
    // priority and CPU like its own threads; not joinable before start().
    std::thread& thread() { return thread_; }

private:
    struct HidSession;
    Outcome choose_backend();
    void run(InputRing& ring, std::promise<Outcome>& started);
    void run_evdev(InputRing& ring, std::promise<Outcome>& started);
    void run_hidraw(InputRing& ring, std::promise<Outcome>& started);
    void run_sdl(InputRing& ring, std::promise<Outcome>& started);
    void read_hid_pad(HidSession& hid, InputRingWriter<InputRing>& writer);
    void reopen_hid_pad(HidSession& hid);
    // Calibrates `sample` and pushes it, counting it when the ring takes it.
    void push_calibrated(InputRingWriter<InputRing>& writer, const FamilyCalibration& cal, InputSample& sample);
    bool stopping() const { return stop_requested_.load(std::memory_order_relaxed); }

    std::thread thread_;
    std::atomic<bool> stop_requested_{false};
    std::atomic<bool> running_{false};
    std::atomic<bool> connected_{false};
    std::atomic<std::uint64_t> samples_{0}, ring_dropped_{0}, rejected_{0}, connects_{0}, disconnects_{0},
        syn_dropped_{0};
    InputThreadOptions options_;
    BackendKind kind_ = BackendKind::none;
    std::string description_;
};

// What `--input auto` would choose now (enumerates hidraw, evdev and SDL2).
BackendChoice probe_input_backend(const std::string& evdev_dir);

}  // namespace marionette::input
