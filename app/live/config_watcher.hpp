#pragma once
// Watches one configuration file with inotify for live tuning. It watches the
// file's folder, not the file, because editors usually save by writing a new
// file and renaming it over the old one (which would end a watch on the file).
// Deleting, renaming away and changing the permissions of the file count as
// edits too, so the reader can say once that it cannot be read any more.
#include <string>

namespace marionette {

class ConfigWatcher {
public:
    // Throws std::runtime_error naming the path when inotify cannot watch it.
    explicit ConfigWatcher(const std::string& path);
    ~ConfigWatcher();
    ConfigWatcher(const ConfigWatcher&) = delete;
    ConfigWatcher& operator=(const ConfigWatcher&) = delete;

    // Non-blocking descriptor to poll() for POLLIN.
    int fd() const { return fd_; }
    // Reads every pending event; true when one was about the watched file.
    bool read_events();
    const std::string& path() const { return path_; }

private:
    std::string path_;
    std::string name_;  // file name inside the watched folder
    int fd_ = -1;
};

}  // namespace marionette
