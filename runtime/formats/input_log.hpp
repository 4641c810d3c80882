#pragma once
// The input log: what the simulation consumed, tick by tick, so a run can be
// replayed bit for bit. Format (versioned, little-endian) in docs/input-log.md.
//
// The encoder and decoder work on bytes in memory and never touch a file; the
// app decides when chunks are written (at least every 250 ms in a live run).
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/errors/import_error.hpp"
#include "runtime/sim/tick_input.hpp"

namespace marionette {

// Version 2 adds the provenance and motion-data lines to the header and state-hash
// checkpoints to the chunks; version 1 logs still decode (without them).
inline constexpr std::uint32_t kInputLogVersion = 2;
inline constexpr std::uint32_t kOldestInputLogVersion = 1;
// PNG-style magic: a high byte, a name, then CR LF ^Z LF so text-mode mangling shows.
inline constexpr unsigned char kInputLogMagic[8] = {0x89, 'M', 'L', 'G', '\r', '\n', 0x1a, '\n'};

struct InputLogHeader {
    std::uint32_t version = kInputLogVersion;
    std::uint32_t tick_rate_hz = 240;
    std::uint64_t clip_data_hash = 0;
    std::string config_text;  // the effective configuration, TOML
    // Version 2: what recorded the log ("marionette 0.1.0; GCC 12.2.0; x86_64; ..."),
    // named when a replay diverges from it.
    std::string provenance;
    // Version 2: the motion data the log needs besides the build itself: "" (the
    // gait only), "default-graph HASH" (the embedded default graph) or
    // "graph-file HASH PATH" (a .mgraph file; HASH is the XXH64 of its bytes, hex).
    std::string motion_data;
};

// A state-hash checkpoint: hash_state() after `after_ticks` ticks were stepped.
struct InputLogCheckpoint {
    std::uint64_t after_ticks = 0;
    std::uint64_t state_hash = 0;
};
// The recorders write a checkpoint every this many ticks (1 s at 240 Hz) and one at the end.
inline constexpr std::uint64_t kCheckpointIntervalTicks = 240;

// A configuration change recorded in the log: it takes effect before the tick
// with index `before_tick` (0-based), i.e. at a tick boundary.
struct InputLogConfigChange {
    std::uint64_t before_tick = 0;
    std::string config_text;
};

// Builds chunks. Appends are cheap and allocation-free once the chunk buffer has
// grown to its working size (reserve() up front for real-time use).
class InputLogEncoder {
public:
    static std::vector<std::uint8_t> encode_header(const InputLogHeader& header);

    void reserve(size_t payload_bytes) { payload_.reserve(payload_bytes); }
    void append_tick(const TickInput& input);
    void append_config_change(std::string_view config_text);
    // The state hash after every tick appended so far (version 2 logs).
    void append_checkpoint(std::uint64_t state_hash);
    // Marks a cleanly finished log; readers warn when it is missing.
    void append_end();

    std::uint32_t pending_ticks() const { return chunk_ticks_ + (run_length_ > 0 ? run_length_ : 0); }
    bool has_pending() const { return !payload_.empty() || run_length_ > 0; }
    // Appends the finished chunk (header + payload + CRC) to `out` and starts a new one.
    void finish_chunk(std::vector<std::uint8_t>& out);

private:
    void flush_run();
    std::vector<std::uint8_t> payload_;
    TickInput previous_{};        // delta base, reset at each chunk
    TickInput run_input_{};
    std::uint32_t run_length_ = 0;
    std::uint64_t next_tick_ = 0; // first tick of the chunk being built
    std::uint64_t chunk_first_tick_ = 0;
    std::uint32_t chunk_ticks_ = 0;
};

// A whole log in one go: header, the ticks in chunks of `chunk_ticks`, end marker.
std::vector<std::uint8_t> encode_input_log(const InputLogHeader& header, const std::vector<TickInput>& ticks,
                                           std::uint32_t chunk_ticks);

struct DecodedInputLog {
    InputLogHeader header;
    std::vector<TickInput> ticks;
    std::vector<InputLogConfigChange> config_changes;  // in tick order
    std::vector<InputLogCheckpoint> checkpoints;       // in tick order (version 2)
    bool complete = false;         // an end marker was read
    // Non-empty when the log is truncated, corrupt or lacks its end marker: says at
    // which byte offset and why; ticks hold everything up to the last good chunk.
    std::string warning;
    std::int64_t good_bytes = 0;   // bytes up to the end of the last good chunk
};

// Decodes a whole log. A bad header is an ImportError (nothing can be replayed);
// a bad or truncated chunk ends decoding with a warning naming the byte offset.
DecodedInputLog decode_input_log(const std::vector<std::uint8_t>& bytes, const std::string& file_name);

}  // namespace marionette
