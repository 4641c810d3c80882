#pragma once
// One evdev gamepad read through libevdev: capability check (a gamepad has
// BTN_GAMEPAD/BTN_SOUTH and ABS_X/ABS_Y), normalisation from each axis's
// absinfo, the kernel's Documentation/input/gamepad.rst code names mapped to the
// sample's positional buttons, SYN_DROPPED resynchronised through libevdev, and
// ENODEV reported as an unplug. The fd is non-blocking; read_frame() never blocks
// or allocates.
#include <cstdint>
#include <memory>
#include <string>

#include "input/evdev/evdev_state.hpp"
#include "input/input_sample.hpp"
#include "runtime/errors/outcome.hpp"

struct libevdev;

namespace marionette::input {

class EvdevPad {
public:
    // Opens and checks the node into `pad`; fails (leaving `pad` null) when it
    // cannot be opened or is not a gamepad.
    static Outcome open(const std::string& path, std::unique_ptr<EvdevPad>& pad);
    ~EvdevPad();
    EvdevPad(const EvdevPad&) = delete;
    EvdevPad& operator=(const EvdevPad&) = delete;

    enum class Status : std::uint8_t { frame, nothing, disconnected };
    // Reads events until a SYN_REPORT completes a frame (Status::frame, `out`
    // holds the full state after it) or nothing more is queued. After SYN_DROPPED
    // the state is re-read from the device and returned as one frame.
    Status read_frame(InputSample& out);

    // Apply each axis's `flat` as a rest zone (off for --raw).
    void set_apply_flat(bool apply) { state_.set_apply_flat(apply); }

    int fd() const { return fd_; }
    const std::string& path() const { return path_; }
    const std::string& name() const { return name_; }
    std::uint16_t vendor_id() const { return vendor_; }
    std::uint16_t product_id() const { return product_; }
    bool kernel_timestamps() const { return kernel_monotonic_; }
    std::uint64_t frames() const { return frames_; }
    std::uint64_t syn_dropped() const { return syn_dropped_; }
    const EvdevAbs& abs(int index) const { return state_.abs(index); }

private:
    EvdevPad() = default;
    void fill_sample(InputSample& out, std::int64_t kernel_ns) const;

    int fd_ = -1;
    libevdev* dev_ = nullptr;
    std::string path_, name_;
    std::uint16_t vendor_ = 0, product_ = 0;
    bool kernel_monotonic_ = false;
    // Axis and button values, frame boundaries: every event libevdev delivers
    // goes through it (input/evdev/evdev_state.hpp).
    EvdevState state_;
    std::uint64_t frames_ = 0, syn_dropped_ = 0;
};

// True when the node's capabilities are a gamepad's.
bool evdev_is_gamepad(const libevdev* dev);

// The current CLOCK_MONOTONIC time in ns.
std::int64_t monotonic_now_ns();

}  // namespace marionette::input
