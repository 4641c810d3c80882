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
struct KeyMap {
    std::uint16_t code;
    Button button;
};
// gamepad.rst: BTN_SOUTH/EAST/NORTH/WEST are positions, whatever the labels.
constexpr KeyMap kKeys[] = {
    {BTN_SOUTH, Button::south},          {BTN_EAST, Button::east},
    {BTN_WEST, Button::west},            {BTN_NORTH, Button::north},
    {BTN_TL, Button::left_shoulder},     {BTN_TR, Button::right_shoulder},
    {BTN_SELECT, Button::back},          {BTN_START, Button::start},
    {BTN_MODE, Button::guide},           {BTN_THUMBL, Button::left_stick},
    {BTN_THUMBR, Button::right_stick},   {BTN_DPAD_UP, Button::dpad_up},
    {BTN_DPAD_DOWN, Button::dpad_down},  {BTN_DPAD_LEFT, Button::dpad_left},
    {BTN_DPAD_RIGHT, Button::dpad_right},
};
enum AxisIndex { kLx, kLy, kRx, kRy, kLt, kRt, kHatX, kHatY };
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
    const std::uint16_t codes[kAxes] = {ABS_X, ABS_Y, ABS_RX, ABS_RY, ABS_Z, ABS_RZ, ABS_HAT0X, ABS_HAT0Y};
    for (int i = 0; i < kAxes; ++i) pad->abs_code_[i] = codes[i];
    if (!libevdev_has_event_code(dev, EV_ABS, ABS_Z) && libevdev_has_event_code(dev, EV_ABS, ABS_HAT2Y))
        pad->abs_code_[kLt] = ABS_HAT2Y;
    if (!libevdev_has_event_code(dev, EV_ABS, ABS_RZ) && libevdev_has_event_code(dev, EV_ABS, ABS_HAT2X))
        pad->abs_code_[kRt] = ABS_HAT2X;
    for (int i = 0; i < kAxes; ++i) {
        const input_absinfo* info = libevdev_get_abs_info(dev, pad->abs_code_[i]);
        if (!info || info->maximum <= info->minimum) continue;
        pad->abs_[i] = {true, info->minimum, info->maximum, info->fuzz, info->flat};
    }
    pad->analog_left_trigger_ = pad->abs_[kLt].present;
    pad->analog_right_trigger_ = pad->abs_[kRt].present;
    opened = std::move(pad);
    return Outcome::success();
}

EvdevPad::~EvdevPad() {
    if (dev_) libevdev_free(dev_);
    if (fd_ >= 0) ::close(fd_);
}

float EvdevPad::axis_value(int i, bool centred) const {
    const EvdevAbs& a = abs_[i];
    if (!a.present) return 0.0f;
    const int v = libevdev_get_event_value(dev_, EV_ABS, abs_code_[i]);
    if (!centred) return normalise_trigger(v, a.min, a.max);
    if (apply_flat_ && a.flat > 0) {
        const std::int64_t centre = static_cast<std::int64_t>(a.min) + (static_cast<std::int64_t>(a.max) - a.min + 1) / 2;
        if (v - centre <= a.flat && centre - v <= a.flat) return 0.0f;
    }
    return normalise_centred(v, a.min, a.max);
}

void EvdevPad::fill_sample(InputSample& s, std::int64_t kernel_ns) const {
    const std::int64_t now = monotonic_now_ns();
    // A kernel stamp is trusted only when it is plausible (not ahead of now, not
    // older than a second): replayed or foreign clocks fall back to the read time.
    s.t_ns = (kernel_monotonic_ && kernel_ns <= now && now - kernel_ns < 1'000'000'000) ? kernel_ns : now;
    s.lx = axis_value(kLx, true);
    s.ly = flip_axis(axis_value(kLy, true));  // evdev y grows downwards
    s.rx = axis_value(kRx, true);
    s.ry = flip_axis(axis_value(kRy, true));
    s.lt = axis_value(kLt, false);
    s.rt = axis_value(kRt, false);
    std::uint32_t b = 0;
    for (const KeyMap& k : kKeys)
        if (libevdev_get_event_value(dev_, EV_KEY, k.code)) b |= button_bit(k.button);
    if (abs_[kHatX].present) {
        const int x = libevdev_get_event_value(dev_, EV_ABS, ABS_HAT0X);
        if (x < 0) b |= button_bit(Button::dpad_left);
        if (x > 0) b |= button_bit(Button::dpad_right);
    }
    if (abs_[kHatY].present) {
        const int y = libevdev_get_event_value(dev_, EV_ABS, ABS_HAT0Y);
        if (y < 0) b |= button_bit(Button::dpad_up);
        if (y > 0) b |= button_bit(Button::dpad_down);
    }
    if (!analog_left_trigger_ && libevdev_get_event_value(dev_, EV_KEY, BTN_TL2)) s.lt = 1.0f;
    if (!analog_right_trigger_ && libevdev_get_event_value(dev_, EV_KEY, BTN_TR2)) s.rt = 1.0f;
    s.buttons = b;
    s.has_device_counter = false;
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
            do {
                rc = libevdev_next_event(dev_, LIBEVDEV_READ_FLAG_SYNC, &ev);
            } while (rc == LIBEVDEV_READ_STATUS_SYNC);
            if (rc == -ENODEV) return Status::disconnected;
            events_in_frame_ = 0;
            fill_sample(out, monotonic_now_ns());
            ++frames_;
            return Status::frame;
        }
        if (rc == -EAGAIN) return Status::nothing;
        if (rc == -ENODEV || rc == -EIO || rc == -EBADF) return Status::disconnected;
        if (rc < 0) return Status::nothing;  // -EINTR and friends: try again on the next wake-up
        if (ev.type == EV_SYN && ev.code == SYN_REPORT) {
            // The kernel never sends an empty frame; one here is the end of a
            // packet lost to SYN_DROPPED that libevdev did not drain. Skipping it
            // makes the result independent of when the drain happened.
            if (events_in_frame_ == 0) continue;
            events_in_frame_ = 0;
            const std::int64_t kernel_ns = static_cast<std::int64_t>(ev.input_event_sec) * 1'000'000'000 +
                                           static_cast<std::int64_t>(ev.input_event_usec) * 1000;
            fill_sample(out, kernel_ns);
            ++frames_;
            return Status::frame;
        }
        if (ev.type != EV_SYN) ++events_in_frame_;
    }
}

}  // namespace marionette::input
