#include "app/live/config_watcher.hpp"

#include <sys/inotify.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace marionette {

ConfigWatcher::ConfigWatcher(const std::string& path) : path_(path) {
    const size_t slash = path.rfind('/');
    const std::string folder = slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
    name_ = slash == std::string::npos ? path : path.substr(slash + 1);
    fd_ = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
    if (fd_ < 0) throw std::runtime_error(path + ": cannot watch for live tuning: inotify: " + std::strerror(errno));
    if (inotify_add_watch(fd_, folder.c_str(), IN_CLOSE_WRITE | IN_MOVED_TO | IN_CREATE | IN_MODIFY | IN_DELETE | IN_MOVED_FROM | IN_ATTRIB) < 0) {
        const int err = errno;
        ::close(fd_);
        throw std::runtime_error(path + ": cannot watch " + folder + " for live tuning: " + std::strerror(err));
    }
}

ConfigWatcher::~ConfigWatcher() {
    if (fd_ >= 0) ::close(fd_);
}

bool ConfigWatcher::read_events() {
    bool ours = false;
    alignas(inotify_event) char buffer[4096];
    for (;;) {
        const ssize_t n = ::read(fd_, buffer, sizeof buffer);
        if (n <= 0) break;  // EAGAIN: drained
        for (ssize_t at = 0; at < n;) {
            inotify_event event;
            std::memcpy(&event, buffer + at, sizeof event);
            if (event.len > 0 && name_ == (buffer + at + sizeof(inotify_event))) ours = true;
            at += static_cast<ssize_t>(sizeof(inotify_event) + event.len);
        }
    }
    return ours;
}

}  // namespace marionette
