#include "input/evdev/evdev_pad.hpp"

#include <fcntl.h>
#include <libevdev/libevdev.h>
#include <linux/input.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace marionette::input {

namespace {
// The pad reads only these keys (EvdevState maps them to buttons).
constexpr std::uint16_t kReadKeys[] = {BTN_SOUTH, BTN_EAST,   BTN_WEST,     BTN_NORTH,     BTN_TL,
                                       BTN_TR,    BTN_SELECT, BTN_START,    BTN_MODE,      BTN_THUMBL,
                                       BTN_THUMBR, BTN_DPAD_UP, BTN_DPAD_DOWN, BTN_DPAD_LEFT, BTN_DPAD_RIGHT,
                                       BTN_TL2,   BTN_TR2};
}  // namespace

std::int64_t monotonic_now_ns() {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

bool evdev_is_gamepad(const libevdev* dev) {
    return libevdev_has_event_code(dev, EV_KEY, BTN_GAMEPAD) && libevdev_has_event_code(dev, EV_ABS, ABS_X) &&
           libevdev_has_event_code(dev, EV_ABS, ABS_Y);
}

Outcome EvdevPad::open(const std::string& path, std::unique_ptr<EvdevPad>& opened) {
    opened.reset();
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        return Outcome::failure(path + ": " + std::strerror(errno));
    }
    libevdev* dev = nullptr;
    const int rc = libevdev_new_from_fd(fd, &dev);
    if (rc < 0) {
        ::close(fd);
        return Outcome::failure(path + ": libevdev cannot read the device: " + std::strerror(-rc));
    }
    if (!evdev_is_gamepad(dev)) {
        libevdev_free(dev);
        ::close(fd);
        return Outcome::failure(path + ": not a gamepad (needs BTN_GAMEPAD and ABS_X/ABS_Y)");
    }
    std::unique_ptr<EvdevPad> pad(new EvdevPad());
    pad->fd_ = fd;
    pad->dev_ = dev;
    pad->path_ = path;
    pad->name_ = libevdev_get_name(dev) ? libevdev_get_name(dev) : "";
    pad->vendor_ = static_cast<std::uint16_t>(libevdev_get_id_vendor(dev));
    pad->product_ = static_cast<std::uint16_t>(libevdev_get_id_product(dev));
    // Kernel timestamps on the monotonic clock are the earliest stamp there is;
    // where the ioctl is refused (umockdev, old kernels) the read time is used.
    pad->kernel_monotonic_ = libevdev_set_clock_id(dev, CLOCK_MONOTONIC) == 0;
    // Triggers: ABS_Z/ABS_RZ (xpad, hid-playstation), else ABS_HAT2Y/ABS_HAT2X (gamepad.rst).
    EvdevState& state = pad->state_;
    if (!libevdev_has_event_code(dev, EV_ABS, ABS_Z) && libevdev_has_event_code(dev, EV_ABS, ABS_HAT2Y))
        state.set_axis_code(EvdevState::kLt, ABS_HAT2Y);
    if (!libevdev_has_event_code(dev, EV_ABS, ABS_RZ) && libevdev_has_event_code(dev, EV_ABS, ABS_HAT2X))
        state.set_axis_code(EvdevState::kRt, ABS_HAT2X);
    for (int i = 0; i < EvdevState::kAxes; ++i) {
        const input_absinfo* info = libevdev_get_abs_info(dev, state.axis_code(i));
        if (!info || info->maximum <= info->minimum) continue;
        state.set_axis_info(i, info->minimum, info->maximum, info->fuzz, info->flat, info->value);
    }
    for (std::uint16_t code : kReadKeys) state.set_key(code, libevdev_get_event_value(dev, EV_KEY, code) != 0);
    opened = std::move(pad);
    return Outcome::success();
}

EvdevPad::~EvdevPad() {
    if (dev_) libevdev_free(dev_);
    if (fd_ >= 0) ::close(fd_);
}

void EvdevPad::fill_sample(InputSample& s, std::int64_t kernel_ns) const {
    const std::int64_t now = monotonic_now_ns();
    // A kernel stamp is trusted only when it is plausible (not ahead of now, not
    // older than a second): replayed or foreign clocks fall back to the read time.
    s.t_ns = (kernel_monotonic_ && kernel_ns <= now && now - kernel_ns < 1'000'000'000) ? kernel_ns : now;
    state_.fill(s);
}

EvdevPad::Status EvdevPad::read_frame(InputSample& out) {
    input_event ev{};
    for (;;) {
        int rc = libevdev_next_event(dev_, LIBEVDEV_READ_FLAG_NORMAL, &ev);
        if (rc == LIBEVDEV_READ_STATUS_SYNC) {
            // The kernel's buffer overflowed: libevdev re-reads the device state
            // and hands the differences as sync events; drain them, then report
            // the resynchronised state as one frame.
            ++syn_dropped_;
            for (;;) {
                rc = libevdev_next_event(dev_, LIBEVDEV_READ_FLAG_SYNC, &ev);
                if (rc != LIBEVDEV_READ_STATUS_SYNC) break;
                state_.on_event(ev.type, ev.code, ev.value);
            }
            if (rc == -ENODEV) return Status::disconnected;
            state_.start_frame();
            fill_sample(out, monotonic_now_ns());
            ++frames_;
            return Status::frame;
        }
        if (rc == -EAGAIN) return Status::nothing;
        if (rc == -ENODEV || rc == -EIO || rc == -EBADF) return Status::disconnected;
        if (rc < 0) return Status::nothing;  // -EINTR and friends: try again on the next wake-up
        // An empty SYN_REPORT (the end of a packet lost to SYN_DROPPED) completes
        // no frame (EvdevState::on_event).
        if (state_.on_event(ev.type, ev.code, ev.value)) {
            const std::int64_t kernel_ns = static_cast<std::int64_t>(ev.input_event_sec) * 1'000'000'000 +
                                           static_cast<std::int64_t>(ev.input_event_usec) * 1000;
            fill_sample(out, kernel_ns);
            ++frames_;
            return Status::frame;
        }
    }
}

}  // namespace marionette::input
