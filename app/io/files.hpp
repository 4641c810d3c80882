#pragma once
// File helpers for the commands: whole-file reads, and an input-log file that
// writes chunks as the run goes so a crash loses at most the unflushed chunk.
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "runtime/formats/input_log.hpp"

namespace marionette {

// Throws ImportError naming the path when it cannot be read.
std::vector<std::uint8_t> read_binary_file(const std::string& path);
std::string read_text_file(const std::string& path);
// Writes atomically enough for outputs (truncate + write); throws std::runtime_error.
void write_text_file(const std::string& path, const std::string& text);

// An input log may span files (app/live/recording.hpp): PATH, then PATH.1,
// PATH.2, ... (continuations holding whole chunks). These list and read them
// in order, as one log; a lone file is just itself.
std::vector<std::string> input_log_files(const std::string& path);

// The local date and time as YYYYMMDD-HHMMSS, for naming files only (a
// recording's name). Calendar time never paces anything: the live pipeline
// reads only CLOCK_MONOTONIC (tests/app/faults, the clock-jump test).
std::string local_date_time_stamp();
std::vector<std::uint8_t> read_input_log_bytes(const std::string& path);

class InputLogFile {
public:
    // Creates the file and writes the header; throws std::runtime_error on failure.
    InputLogFile(const std::string& path, const InputLogHeader& header);
    ~InputLogFile();
    InputLogFile(const InputLogFile&) = delete;
    InputLogFile& operator=(const InputLogFile&) = delete;

    void append_tick(const TickInput& input) { encoder_.append_tick(input); }
    void append_config_change(const std::string& text) { encoder_.append_config_change(text); }
    void append_checkpoint(std::uint64_t state_hash) { encoder_.append_checkpoint(state_hash); }
    std::uint32_t pending_ticks() const { return encoder_.pending_ticks(); }
    // Ends the current chunk and writes it to the file (and the OS).
    void flush();
    // Writes the end marker and closes; the destructor does this too.
    void close();

private:
    std::string path_;
    std::FILE* file_ = nullptr;
    InputLogEncoder encoder_;
    std::vector<std::uint8_t> buffer_;
};

}  // namespace marionette
