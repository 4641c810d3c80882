#include "input/evdev/evdev_backend.hpp"

#include <dirent.h>
#include <sys/epoll.h>
#include <sys/inotify.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace marionette::input {

namespace {
constexpr std::uint64_t kInotifyTag = 0xFFFF'FFFF'FFFF'FFFFull;

bool is_event_node(const char* name) { return std::strncmp(name, "event", 5) == 0 && name[5] >= '0' && name[5] <= '9'; }

std::vector<std::string> event_nodes(const std::string& dir) {
    std::vector<std::string> out;
    if (DIR* d = opendir(dir.c_str())) {
        while (const dirent* e = readdir(d))
            if (is_event_node(e->d_name)) out.push_back(dir + "/" + e->d_name);
        closedir(d);
    }
    // eventN in numeric order, so device ids follow the kernel's order.
    std::sort(out.begin(), out.end(), [](const std::string& a, const std::string& b) {
        return a.size() != b.size() ? a.size() < b.size() : a < b;
    });
    return out;
}
}  // namespace

std::vector<EvdevDeviceInfo> enumerate_evdev_gamepads(const std::string& dir) {
    std::vector<EvdevDeviceInfo> out;
    for (const std::string& path : event_nodes(dir)) {
        std::unique_ptr<EvdevPad> pad;
        if (EvdevPad::open(path, pad).ok())
            out.push_back({path, pad->name(), pad->vendor_id(), pad->product_id()});
    }
    return out;
}

EvdevBackend::EvdevBackend() { epoll_fd_ = epoll_create1(EPOLL_CLOEXEC); }

EvdevBackend::~EvdevBackend() {
    for (int i = 0; i < kMaxPads; ++i) pads_[static_cast<std::size_t>(i)].reset();
    if (inotify_fd_ >= 0) ::close(inotify_fd_);
    if (epoll_fd_ >= 0) ::close(epoll_fd_);
}

Outcome EvdevBackend::watch_directory(const std::string& dir) {
    if (epoll_fd_ < 0) return Outcome::failure(std::string("epoll_create1: ") + std::strerror(errno));
    dir_ = dir;
    inotify_fd_ = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
    if (inotify_fd_ >= 0) {
        epoll_event ev{};
        ev.events = EPOLLIN;
        ev.data.u64 = kInotifyTag;
        epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, inotify_fd_, &ev);
        add_watch();
    }
    scan_directory();
    return Outcome::success();
}

bool EvdevBackend::add_watch() {
    // IN_ATTRIB: udev sets permissions after the node appears, so a node we
    // could not open at IN_CREATE is retried then.
    watching_ = inotify_fd_ >= 0 &&
                inotify_add_watch(inotify_fd_, dir_.c_str(), IN_CREATE | IN_ATTRIB | IN_DELETE | IN_MOVED_TO) >= 0;
    return watching_;
}

Outcome EvdevBackend::open_device(const std::string& path) {
    const std::size_t slash = path.rfind('/');
    only_path_ = path;
    if (Outcome watched = watch_directory(slash == std::string::npos ? "." : path.substr(0, slash)); !watched.ok())
        return watched;
    if (connected() == 0) {
        std::unique_ptr<EvdevPad> probe;
        const Outcome opened = EvdevPad::open(path, probe);  // for the message
        return Outcome::failure(opened.ok() ? path + ": cannot open" : opened.problem());
    }
    return Outcome::success();
}

void EvdevBackend::scan_directory() {
    for (const std::string& path : event_nodes(dir_)) try_open(path);
}

bool EvdevBackend::try_open(const std::string& path) {
    if (!only_path_.empty() && path != only_path_) return true;
    int free_slot = -1;
    for (int i = 0; i < kMaxPads; ++i) {
        const auto& p = pads_[static_cast<std::size_t>(i)];
        if (p && p->path() == path) return true;  // already open
        if (!p && free_slot < 0) free_slot = i;
    }
    if (free_slot < 0) return true;
    std::unique_ptr<EvdevPad> pad;
    if (!EvdevPad::open(path, pad).ok()) return false;
    pad->set_apply_flat(!raw_);
    epoll_event ev{};
    ev.events = EPOLLIN;
    ev.data.u64 = static_cast<std::uint64_t>(free_slot);
    if (epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, pad->fd(), &ev) < 0) return false;
    pads_[static_cast<std::size_t>(free_slot)] = std::move(pad);
    ++connects_;
    return true;
}

void EvdevBackend::remember_pending(const std::string& path) {
    // Not openable yet: keep trying for a while (a node that is not a gamepad at
    // all just times out).
    for (Pending& p : pending_)
        if (p.path.empty() || p.path == path) {
            p.path = path;
            p.until_ns = monotonic_now_ns() + 2'000'000'000;
            return;
        }
}

void EvdevBackend::retry_pending(std::int64_t now) {
    for (Pending& p : pending_) {
        if (p.path.empty()) continue;
        if (try_open(p.path) || now > p.until_ns) p.path.clear();
    }
}

void EvdevBackend::close_slot(int slot) {
    auto& p = pads_[static_cast<std::size_t>(slot)];
    if (!p) return;
    epoll_ctl(epoll_fd_, EPOLL_CTL_DEL, p->fd(), nullptr);
    closed_syn_dropped_ += p->syn_dropped();
    p.reset();
    ++disconnects_;
}

void EvdevBackend::handle_inotify() {
    alignas(inotify_event) char buf[4096];
    for (;;) {
        const ssize_t n = ::read(inotify_fd_, buf, sizeof buf);
        if (n <= 0) return;
        for (ssize_t at = 0; at < n;) {
            const auto* e = reinterpret_cast<const inotify_event*>(buf + at);
            at += static_cast<ssize_t>(sizeof(inotify_event) + e->len);
            // The directory itself went away (the last pad unplugged on some
            // systems, or a test bed): watch again once it is back.
            if (e->mask & IN_IGNORED) watching_ = false;
            if (e->len == 0 || !is_event_node(e->name)) continue;
            const std::string path = dir_ + "/" + e->name;
            if (e->mask & IN_DELETE) {
                for (int i = 0; i < kMaxPads; ++i)
                    if (pads_[static_cast<std::size_t>(i)] && pads_[static_cast<std::size_t>(i)]->path() == path) close_slot(i);
            } else if (!try_open(path) && (e->mask & IN_CREATE)) {
                remember_pending(path);
            }
        }
    }
}

int EvdevBackend::poll(std::span<InputSample> out, int timeout_ms) {
    epoll_event events[kMaxPads + 1];
    const int n = epoll_wait(epoll_fd_, events, kMaxPads + 1, timeout_ms);
    int produced = 0;
    bool any_pending = false;
    for (const Pending& p : pending_) any_pending = any_pending || !p.path.empty();
    if (any_pending) {
        const std::int64_t now = monotonic_now_ns();
        if (now - last_pending_retry_ns_ >= 100'000'000) {
            last_pending_retry_ns_ = now;
            retry_pending(now);
        }
    }
    if (!watching_ && inotify_fd_ >= 0) {
        const std::int64_t now = monotonic_now_ns();
        if (now - last_watch_retry_ns_ >= kWatchRetryNs) {
            last_watch_retry_ns_ = now;
            // The directory is back: what is in it now arrived while unwatched.
            if (add_watch())
                for (const std::string& path : event_nodes(dir_))
                    if (!try_open(path)) remember_pending(path);
        }
    }
    for (int i = 0; i < n; ++i) {
        if (events[i].data.u64 == kInotifyTag) {
            handle_inotify();
            continue;
        }
        const int slot = static_cast<int>(events[i].data.u64);
        EvdevPad* pad = pads_[static_cast<std::size_t>(slot)].get();
        if (!pad) continue;
        bool gone = false;
        while (produced < static_cast<int>(out.size())) {
            InputSample& s = out[static_cast<std::size_t>(produced)];
            const EvdevPad::Status st = pad->read_frame(s);
            if (st == EvdevPad::Status::frame) {
                s.device_id = static_cast<std::uint32_t>(slot);
                ++produced;
                continue;
            }
            gone = st == EvdevPad::Status::disconnected;
            break;
        }
        // A hang-up with nothing left to read is an unplug too (EOF instead of ENODEV).
        if (!gone && (events[i].events & (EPOLLHUP | EPOLLERR))) {
            InputSample probe;
            gone = pad->read_frame(probe) != EvdevPad::Status::frame;
        }
        if (gone) close_slot(slot);
    }
    return produced;
}

void EvdevBackend::set_raw(bool raw) {
    raw_ = raw;
    for (auto& p : pads_)
        if (p) p->set_apply_flat(!raw);
}

int EvdevBackend::connected() const {
    int n = 0;
    for (const auto& p : pads_) n += p ? 1 : 0;
    return n;
}

std::uint64_t EvdevBackend::syn_dropped() const {
    std::uint64_t n = closed_syn_dropped_;
    for (const auto& p : pads_)
        if (p) n += p->syn_dropped();
    return n;
}

}  // namespace marionette::input
