#pragma once
// Where `run` records its input log, and how it keeps the disk from filling
// (docs/deploy.md "Recordings", docs/config.md [recording]).
//
// A recording is one log split across files: NAME, then NAME.1, NAME.2, ...
// Each continuation file holds whole chunks only, so the files concatenated in
// order are exactly one log (`replay NAME` reads them so, app/io/files.hpp
// read_input_log_bytes). A file that would pass `max_file_bytes` continues in
// the next one. With a rotation directory (`--record auto`), the oldest
// recordings there are deleted whole, oldest first, to keep all of them under
// `max_total_bytes` and at least `min_free_bytes` free on the file system.
// When a write fails (a full disk: ENOSPC) or no room can be made, the recording
// ends cleanly: the partly written chunk is cut off, every finished chunk stays
// readable, one message says so, and the run goes on without recording.
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "runtime/formats/input_log.hpp"

namespace marionette {

struct RecordingConfig;

struct RecordingLimits {
    std::int64_t max_total_bytes = 0;  // rotation directory only; 0: no cap
    std::int64_t max_file_bytes = 0;   // 0: one file
    std::int64_t min_free_bytes = 0;   // 0: write until the disk is full
};
RecordingLimits recording_limits(const RecordingConfig& config);

struct RecordingOptions {
    std::string file;        // the recording's first file
    std::string rotate_dir;  // non-empty: delete the oldest recordings here to keep the limits
    RecordingLimits limits;
};

// The service's state directory ($STATE_DIRECTORY, set by systemd's
// StateDirectory=) + "/recordings", else $XDG_STATE_HOME/marionette/recordings,
// else ~/.local/state/marionette/recordings.
std::string default_recordings_dir();
// A new recording's first file in `dir`: run-YYYYMMDD-HHMMSS.mlog (local time;
// -2, -3, ... when taken). Creates `dir` (and its parents) when missing; throws
// std::runtime_error naming it when that fails.
std::string new_recording_path(const std::string& dir);
// The files of the recording that starts at `first`: it, then first.1, first.2, ... while they exist.
std::vector<std::string> recording_files(const std::string& first);

class RecordingSink {
public:
    // Creates the first file (removing continuation files a previous recording
    // of that name left) and writes the header. Throws std::runtime_error when
    // the file cannot be created; a full disk already ends the recording (one
    // message on `err`) and the run goes on.
    RecordingSink(const RecordingOptions& options, const InputLogHeader& header, std::FILE* err);
    ~RecordingSink();
    RecordingSink(const RecordingSink&) = delete;
    RecordingSink& operator=(const RecordingSink&) = delete;

    void append_tick(const TickInput& input);
    void append_config_change(const std::string& text);
    void append_checkpoint(std::uint64_t state_hash);
    std::uint32_t pending_ticks() const { return recording_ ? encoder_.pending_ticks() : 0; }
    // Ends the current chunk and writes it (never throws: a failure ends the recording).
    void flush();
    // Writes the end marker and closes the file.
    void close();

    bool recording() const { return recording_; }
    const std::string& stop_reason() const { return stop_reason_; }  // "" while recording or closed normally
    std::uint64_t ticks_written() const { return ticks_written_; }
    const std::vector<std::string>& files() const { return files_; }
    std::uint64_t recordings_deleted() const { return deleted_; }

private:
    bool write_chunk();
    bool make_room(std::int64_t bytes);
    bool open_next_file();
    bool write_all(const std::uint8_t* data, size_t size);
    void stop(const std::string& why);

    RecordingOptions options_;
    std::FILE* err_;
    int fd_ = -1;
    std::int64_t header_bytes_ = 0;
    std::int64_t file_bytes_ = 0;       // in the current file
    std::int64_t recording_bytes_ = 0;  // in all of this recording's files
    std::int64_t others_bytes_ = 0;     // the other recordings in the rotation directory
    InputLogEncoder encoder_;
    std::vector<std::uint8_t> buffer_;
    std::vector<std::string> files_;
    bool recording_ = false;
    std::string stop_reason_;
    std::uint64_t ticks_appended_ = 0;
    std::uint64_t ticks_written_ = 0;
    std::uint64_t deleted_ = 0;
};

}  // namespace marionette
