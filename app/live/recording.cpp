#include "app/live/recording.hpp"
#include "app/io/log.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <pwd.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <system_error>

#include "app/config/app_config.hpp"
#include "app/io/files.hpp"

namespace marionette {

namespace fs = std::filesystem;

namespace {

std::int64_t megabytes(float mb) { return static_cast<std::int64_t>(std::llround(static_cast<double>(mb) * 1e6)); }

std::string env_dir(const char* name) {
    const char* v = std::getenv(name);
    return v != nullptr && v[0] == '/' ? std::string(v) : std::string();
}

std::string home_dir() {
    if (std::string home = env_dir("HOME"); !home.empty()) return home;
    if (const passwd* pw = getpwuid(getuid()); pw != nullptr && pw->pw_dir != nullptr) return pw->pw_dir;
    return "/tmp";
}

// A recording's files: its first file NAME.mlog (or any name given) and NAME.N continuations.
struct StoredRecording {
    std::int64_t bytes = 0;
    fs::file_time_type newest{};
};

// The recordings in `dir` by first file, except `current`'s. Names: *.mlog and *.mlog.N.
std::map<std::string, StoredRecording> stored_recordings(const std::string& dir, const std::string& current) {
    std::map<std::string, StoredRecording> out;
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        if (!it->is_regular_file(ec)) continue;
        std::string name = it->path().filename().string();
        if (const size_t dot = name.rfind('.'); dot != std::string::npos &&
                                                 name.find_first_not_of("0123456789", dot + 1) == std::string::npos &&
                                                 dot + 1 < name.size())
            name.resize(dot);  // a continuation: NAME.N belongs to NAME
        if (name.size() < 5 || name.compare(name.size() - 5, 5, ".mlog") != 0) continue;
        const std::string first = (fs::path(dir) / name).string();
        if (first == current) continue;
        StoredRecording& r = out[first];
        r.bytes += static_cast<std::int64_t>(it->file_size(ec));
        const fs::file_time_type t = it->last_write_time(ec);
        if (t > r.newest) r.newest = t;
    }
    return out;
}

std::int64_t free_bytes(const std::string& dir) {
    struct statvfs st {};
    if (statvfs(dir.c_str(), &st) != 0) return -1;
    return static_cast<std::int64_t>(st.f_bavail) * static_cast<std::int64_t>(st.f_frsize);
}

}  // namespace

RecordingLimits recording_limits(const RecordingConfig& config) {
    return {megabytes(config.max_total_mb), megabytes(config.max_file_mb), megabytes(config.min_free_mb)};
}

std::string default_recordings_dir() {
    // systemd may list several state directories, separated by colons: the first is ours.
    std::string state = env_dir("STATE_DIRECTORY");
    if (!state.empty()) return state.substr(0, state.find(':')) + "/recordings";
    std::string xdg = env_dir("XDG_STATE_HOME");
    if (xdg.empty()) xdg = home_dir() + "/.local/state";
    return xdg + "/marionette/recordings";
}

std::string new_recording_path(const std::string& dir) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir, ec))
        throw std::runtime_error(dir + ": cannot create the recordings directory: " + (ec ? ec.message() : "not a directory"));
    const std::string stamp = local_date_time_stamp();
    for (int n = 1;; ++n) {
        const std::string path = fmt::format("{}/run-{}{}.mlog", dir, stamp, n == 1 ? "" : fmt::format("-{}", n));
        if (!fs::exists(path, ec)) return path;
    }
}

std::vector<std::string> recording_files(const std::string& first) { return input_log_files(first); }

RecordingSink::RecordingSink(const RecordingOptions& options, const InputLogHeader& header, std::FILE* err)
    : options_(options), err_(err) {
    // Continuations a previous recording of this name left would be read as ours.
    for (const std::string& old : input_log_files(options_.file))
        if (old != options_.file) ::unlink(old.c_str());
    fd_ = ::open(options_.file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd_ < 0) throw std::runtime_error(options_.file + ": cannot create input log: " + std::strerror(errno));
    files_.push_back(options_.file);
    recording_ = true;
    if (!options_.rotate_dir.empty())
        for (const auto& [name, r] : stored_recordings(options_.rotate_dir, options_.file)) others_bytes_ += r.bytes;
    encoder_.reserve(4096);
    buffer_ = InputLogEncoder::encode_header(header);
    if (!make_room(static_cast<std::int64_t>(buffer_.size()))) return;
    if (!write_all(buffer_.data(), buffer_.size())) {
        stop(fmt::format("{}: {}", options_.file, std::strerror(errno)));
        return;
    }
    file_bytes_ = recording_bytes_ = header_bytes_ = static_cast<std::int64_t>(buffer_.size());
    buffer_.clear();
}

RecordingSink::~RecordingSink() { close(); }

void RecordingSink::append_tick(const TickInput& input) {
    if (!recording_) return;
    encoder_.append_tick(input);
    ++ticks_appended_;
}

void RecordingSink::append_config_change(const std::string& text) {
    if (recording_) encoder_.append_config_change(text);
}

void RecordingSink::append_checkpoint(std::uint64_t state_hash) {
    if (recording_) encoder_.append_checkpoint(state_hash);
}

void RecordingSink::flush() {
    if (recording_) write_chunk();
}

void RecordingSink::close() {
    if (recording_) {
        encoder_.append_end();
        write_chunk();
    }
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    recording_ = false;
}

bool RecordingSink::write_chunk() {
    buffer_.clear();
    encoder_.finish_chunk(buffer_);
    if (buffer_.empty()) return true;
    const auto size = static_cast<std::int64_t>(buffer_.size());
    // A file holds at least one chunk (past its header, in the first file).
    if (options_.limits.max_file_bytes > 0 && file_bytes_ + size > options_.limits.max_file_bytes &&
        file_bytes_ > (files_.size() == 1 ? header_bytes_ : 0) && !open_next_file())
        return false;
    if (!make_room(size)) return false;
    if (!write_all(buffer_.data(), buffer_.size())) {
        const int error = errno;
        // Cut the partly written chunk off: the file ends with its last whole chunk.
        if (ftruncate(fd_, file_bytes_) != 0) { /* the reader stops at the torn chunk anyway */ }
        stop(fmt::format("{}: {}", files_.back(), std::strerror(error)));
        return false;
    }
    file_bytes_ += size;
    recording_bytes_ += size;
    ticks_written_ = ticks_appended_;
    buffer_.clear();
    return true;
}

bool RecordingSink::open_next_file() {
    const std::string next = fmt::format("{}.{}", options_.file, files_.size());
    const int fd = ::open(next.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) {
        stop(fmt::format("{}: cannot create the next file: {}", next, std::strerror(errno)));
        return false;
    }
    ::close(fd_);
    fd_ = fd;
    files_.push_back(next);
    file_bytes_ = 0;
    return true;
}

// Deletes the oldest other recordings in the rotation directory until `bytes`
// more fit under max_total_bytes and leave min_free_bytes free; false (and the
// recording ends) when they cannot.
bool RecordingSink::make_room(std::int64_t bytes) {
    const RecordingLimits& l = options_.limits;
    const std::string dir = fs::path(options_.file).parent_path().string();
    auto over_total = [&] {
        return !options_.rotate_dir.empty() && l.max_total_bytes > 0 &&
               others_bytes_ + recording_bytes_ + bytes > l.max_total_bytes;
    };
    auto short_of_space = [&] {
        if (l.min_free_bytes <= 0) return false;
        const std::int64_t free = free_bytes(dir.empty() ? "." : dir);
        return free >= 0 && free - bytes < l.min_free_bytes;
    };
    if (!over_total() && !short_of_space()) return true;
    if (!options_.rotate_dir.empty()) {
        std::map<std::string, StoredRecording> stored = stored_recordings(options_.rotate_dir, options_.file);
        others_bytes_ = 0;
        for (const auto& [name, r] : stored) others_bytes_ += r.bytes;
        std::vector<std::pair<fs::file_time_type, std::string>> oldest_first;
        for (const auto& [name, r] : stored) oldest_first.emplace_back(r.newest, name);
        std::sort(oldest_first.begin(), oldest_first.end());
        for (const auto& [time, name] : oldest_first) {
            if (!over_total() && !short_of_space()) break;
            for (const std::string& file : input_log_files(name)) ::unlink(file.c_str());
            others_bytes_ -= stored[name].bytes;
            ++deleted_;
            log_message(LogLevel::info, fmt::format("marionette: recording: deleted the oldest recording {} ({} bytes) to make room", name,
                       stored[name].bytes), err_);
        }
    }
    if (over_total()) {
        stop(fmt::format("{} reached [recording] max_total_mb ({:.2f} MB) by itself", options_.file,
                         static_cast<double>(l.max_total_bytes) / 1e6));
        return false;
    }
    if (short_of_space()) {
        stop(fmt::format("{}: less than [recording] min_free_mb ({:.2f} MB) would be left free", dir,
                         static_cast<double>(l.min_free_bytes) / 1e6));
        return false;
    }
    return true;
}

bool RecordingSink::write_all(const std::uint8_t* data, size_t size) {
    while (size > 0) {
        const ssize_t n = ::write(fd_, data, size);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            if (n == 0) errno = ENOSPC;
            return false;
        }
        data += n;
        size -= static_cast<size_t>(n);
    }
    return true;
}

void RecordingSink::stop(const std::string& why) {
    if (!recording_) return;
    recording_ = false;
    stop_reason_ = why;
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    // A continuation file that got nothing, or a first file without its whole header, holds nothing to replay.
    if (file_bytes_ == 0) {
        ::unlink(files_.back().c_str());
        files_.pop_back();
    }
    std::string kept = files_.empty() ? "nothing was kept" : fmt::format("the {} ticks before it stay replayable in {}", ticks_written_, files_.front());
    if (files_.size() > 1) kept += fmt::format(" (and {} continuation file{})", files_.size() - 1, files_.size() > 2 ? "s" : "");
    log_message(LogLevel::error, fmt::format("error: recording stopped: {}; {}; the run goes on without recording", why, kept), err_);
    std::fflush(err_);
}

}  // namespace marionette
