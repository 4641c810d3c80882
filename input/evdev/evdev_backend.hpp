#pragma once
// Every evdev gamepad under a directory (/dev/input, or the one umockdev
// provides), in one epoll set with an inotify watch on the directory: new
// event* nodes are opened when they appear (hot-plug), pads whose read fails
// with ENODEV or whose node disappears are closed (unplug). poll() never
// blocks longer than its timeout; it allocates only when a pad is plugged in
// (libevdev's own state).
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "input/evdev/evdev_pad.hpp"

namespace marionette::input {

struct EvdevDeviceInfo {
    std::string path, name;
    std::uint16_t vendor_id = 0, product_id = 0;
};
// Gamepads under `dir` now (event* nodes that open and pass the capability check).
std::vector<EvdevDeviceInfo> enumerate_evdev_gamepads(const std::string& dir = "/dev/input");

class EvdevBackend {
public:
    static constexpr int kMaxPads = 8;

    EvdevBackend();
    ~EvdevBackend();
    EvdevBackend(const EvdevBackend&) = delete;
    EvdevBackend& operator=(const EvdevBackend&) = delete;

    // Watch a directory: open its gamepads now and whenever one appears.
    Outcome watch_directory(const std::string& dir);
    // One node only (--device PATH); reopened if it reappears in its directory.
    Outcome open_device(const std::string& path);

    // Waits up to timeout_ms, then returns the samples read (at most out.size()).
    int poll(std::span<InputSample> out, int timeout_ms);

    void set_raw(bool raw);
    int connected() const;
    std::uint64_t connects() const { return connects_; }
    std::uint64_t disconnects() const { return disconnects_; }
    std::uint64_t syn_dropped() const;
    const EvdevPad* pad(int slot) const { return pads_[static_cast<std::size_t>(slot)].get(); }
    int epoll_fd() const { return epoll_fd_; }

private:
    void scan_directory();
    bool try_open(const std::string& path);
    void close_slot(int slot);
    void handle_inotify();
    bool add_watch();
    void retry_pending(std::int64_t now);
    void remember_pending(const std::string& path);
    // Nodes that appeared but could not be opened yet (udev still setting
    // permissions, or a test bed still loading the device's ioctls): retried
    // every 100 ms for 2 s.
    struct Pending {
        std::string path;
        std::int64_t until_ns = 0;
    };
    std::array<Pending, kMaxPads> pending_{};
    std::int64_t last_pending_retry_ns_ = 0;
    static constexpr std::int64_t kWatchRetryNs = 250'000'000;

    int epoll_fd_ = -1;
    int inotify_fd_ = -1;
    bool watching_ = false;
    std::int64_t last_watch_retry_ns_ = 0;
    std::string dir_;
    std::string only_path_;  // --device: the one node to (re)open
    bool raw_ = false;
    std::array<std::unique_ptr<EvdevPad>, kMaxPads> pads_;
    std::uint64_t connects_ = 0, disconnects_ = 0, closed_syn_dropped_ = 0;
};

}  // namespace marionette::input
