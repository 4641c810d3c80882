#include "runtime/formats/input_log.hpp"

#include <zlib.h>

#include <cstring>
#include <limits>
#include <optional>

namespace marionette {

namespace {
constexpr unsigned char kChunkMagic[4] = {'C', 'H', 'N', 'K'};
constexpr size_t kChunkHeaderSize = 4 + 8 + 4 + 4 + 4;  // magic, first tick, ticks, payload size, crc
// Payload tags. 0x00–0x7F: a tick record whose low 7 bits say which fields changed.
constexpr std::uint8_t kTickRecordTagLimit = 0x80;  // tags below it are tick records
constexpr std::uint8_t kTagConfigChange = 0x80;
constexpr std::uint8_t kTagEnd = 0x81;
constexpr std::uint8_t kTagCheckpoint = 0x82;  // then the state hash, 8 bytes little-endian
// Bounds that keep a corrupt length from allocating absurd amounts.
constexpr std::uint32_t kMaxConfigBytes = 1u << 20;
constexpr std::uint32_t kMaxChunkPayload = 64u << 20;
constexpr std::uint32_t kMaxChunkTicks = 1u << 24;  // ~19 h at 240 Hz; writers flush far sooner
constexpr int kFieldCount = 7;
// The largest change between two in-range field values (buttons: 0 .. 2^32-1).
constexpr std::int64_t kMaxFieldDelta = 0xffffffffll;
constexpr const char* kFieldNames[kFieldCount] = {"left_x",       "left_y",        "right_x", "right_y",
                                                   "left_trigger", "right_trigger", "buttons"};

void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void put_u64(std::vector<std::uint8_t>& out, std::uint64_t v) {
    for (int i = 0; i < 8; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void put_varint(std::vector<std::uint8_t>& out, std::uint64_t v) {
    while (v >= 0x80) {
        out.push_back(static_cast<std::uint8_t>(v | 0x80));
        v >>= 7;
    }
    out.push_back(static_cast<std::uint8_t>(v));
}
std::uint64_t zigzag(std::int64_t v) { return (static_cast<std::uint64_t>(v) << 1) ^ static_cast<std::uint64_t>(v >> 63); }
std::int64_t unzigzag(std::uint64_t v) { return static_cast<std::int64_t>(v >> 1) ^ -static_cast<std::int64_t>(v & 1); }

std::uint32_t get_u32(const std::uint8_t* p) {
    std::uint32_t v = 0;
    for (int i = 3; i >= 0; --i) v = (v << 8) | p[i];
    return v;
}
std::uint64_t get_u64(const std::uint8_t* p) {
    std::uint64_t v = 0;
    for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
    return v;
}
std::uint32_t crc32_of(const std::uint8_t* data, size_t size, std::uint32_t seed = 0) {
    return static_cast<std::uint32_t>(::crc32(seed, data, static_cast<uInt>(size)));
}

// Field values as signed 64-bit, in a fixed order: lx ly rx ry lt rt buttons.
void fields_of(const TickInput& in, std::int64_t (&f)[kFieldCount]) {
    f[0] = in.left_x; f[1] = in.left_y; f[2] = in.right_x; f[3] = in.right_y;
    f[4] = in.left_trigger; f[5] = in.right_trigger; f[6] = in.buttons;
}

// Cursor over one chunk payload; every read is bounds-checked.
struct Reader {
    const std::uint8_t* data;
    size_t size;
    size_t pos = 0;
    bool varint(std::uint64_t& v) {
        v = 0;
        for (int shift = 0; shift < 64; shift += 7) {
            if (pos >= size) return false;
            const std::uint8_t b = data[pos++];
            v |= static_cast<std::uint64_t>(b & 0x7f) << shift;
            if (!(b & 0x80)) return true;
        }
        return false;
    }
};
}  // namespace

std::vector<std::uint8_t> InputLogEncoder::encode_header(const InputLogHeader& h) {
    std::vector<std::uint8_t> out(std::begin(kInputLogMagic), std::end(kInputLogMagic));
    put_u32(out, h.version);
    put_u32(out, h.tick_rate_hz);
    put_u64(out, h.clip_data_hash);
    put_u32(out, static_cast<std::uint32_t>(h.config_text.size()));
    out.insert(out.end(), h.config_text.begin(), h.config_text.end());
    if (h.version >= 2) {
        for (const std::string* text : {&h.provenance, &h.motion_data}) {
            put_u32(out, static_cast<std::uint32_t>(text->size()));
            out.insert(out.end(), text->begin(), text->end());
        }
    }
    put_u32(out, crc32_of(out.data(), out.size()));
    return out;
}

void InputLogEncoder::flush_run() {
    if (run_length_ == 0) return;
    std::int64_t now[kFieldCount];
    std::int64_t before[kFieldCount];
    fields_of(run_input_, now);
    fields_of(previous_, before);
    std::uint8_t mask = 0;
    for (int i = 0; i < kFieldCount; ++i)
        if (now[i] != before[i]) mask = static_cast<std::uint8_t>(mask | (1u << i));
    payload_.push_back(mask);
    for (int i = 0; i < kFieldCount; ++i)
        if (mask & (1u << i)) put_varint(payload_, zigzag(now[i] - before[i]));
    put_varint(payload_, run_length_);
    previous_ = run_input_;
    chunk_ticks_ += run_length_;
    run_length_ = 0;
}

void InputLogEncoder::append_tick(const TickInput& input) {
    if (run_length_ > 0 && input == run_input_) {
        ++run_length_;
    } else {
        flush_run();
        run_input_ = input;
        run_length_ = 1;
    }
    ++next_tick_;
}

void InputLogEncoder::append_config_change(std::string_view text) {
    flush_run();
    payload_.push_back(kTagConfigChange);
    put_varint(payload_, text.size());
    payload_.insert(payload_.end(), text.begin(), text.end());
}

void InputLogEncoder::append_checkpoint(std::uint64_t state_hash) {
    flush_run();
    payload_.push_back(kTagCheckpoint);
    for (int i = 0; i < 8; ++i) payload_.push_back(static_cast<std::uint8_t>(state_hash >> (8 * i)));
}

void InputLogEncoder::append_end() {
    flush_run();
    payload_.push_back(kTagEnd);
}

void InputLogEncoder::finish_chunk(std::vector<std::uint8_t>& out) {
    flush_run();
    if (payload_.empty()) return;
    const size_t start = out.size();
    out.insert(out.end(), std::begin(kChunkMagic), std::end(kChunkMagic));
    put_u64(out, chunk_first_tick_);
    put_u32(out, chunk_ticks_);
    put_u32(out, static_cast<std::uint32_t>(payload_.size()));
    // CRC over the chunk's fields after the magic, then the payload.
    std::uint32_t crc = crc32_of(out.data() + start + 4, 16);
    crc = crc32_of(payload_.data(), payload_.size(), crc);
    put_u32(out, crc);
    out.insert(out.end(), payload_.begin(), payload_.end());
    payload_.clear();
    previous_ = TickInput{};
    chunk_first_tick_ = next_tick_;
    chunk_ticks_ = 0;
}

std::vector<std::uint8_t> encode_input_log(const InputLogHeader& header, const std::vector<TickInput>& ticks,
                                           std::uint32_t chunk_ticks) {
    std::vector<std::uint8_t> out = InputLogEncoder::encode_header(header);
    InputLogEncoder encoder;
    for (const TickInput& input : ticks) {
        encoder.append_tick(input);
        if (chunk_ticks > 0 && encoder.pending_ticks() >= chunk_ticks) encoder.finish_chunk(out);
    }
    encoder.append_end();
    encoder.finish_chunk(out);
    return out;
}

namespace {

constexpr size_t kFixedHeaderSize = 8 + 4 + 4 + 8 + 4;  // magic, version, tick rate, clip-data hash, config length
constexpr size_t kCrcSize = 4;
constexpr std::uint32_t kMaxTickRateHz = 100000;

// Version 2: the provenance and motion-data texts after the configuration, each
// a 4-byte length and its bytes. Returns the offset after them (the header CRC).
size_t decode_header_texts(const std::uint8_t* data, size_t size, const std::string& file, size_t at,
                           InputLogHeader& header) {
    for (std::string* text : {&header.provenance, &header.motion_data}) {
        if (size - at < 4 + kCrcSize)
            throw import_error_at_byte(file, static_cast<std::int64_t>(at), "header ends inside its provenance fields");
        const std::uint32_t length = get_u32(data + at);
        if (length > kMaxConfigBytes || length > size - at - 4 - kCrcSize)
            throw import_error_at_byte(file, static_cast<std::int64_t>(at),
                                       "header text length " + std::to_string(length) + " exceeds the file");
        text->assign(reinterpret_cast<const char*>(data + at + 4), length);
        at += 4 + length;
    }
    return at;
}

// Reads and checks the header; a bad one throws (nothing can be replayed
// without it). Returns the offset of the first chunk.
size_t decode_header(const std::uint8_t* data, size_t size, const std::string& file, InputLogHeader& header) {
    if (size < kFixedHeaderSize + kCrcSize)
        throw import_error_at_byte(file, 0, "file is too short to be an input log (" + std::to_string(size) + " bytes)");
    if (std::memcmp(data, kInputLogMagic, 8) != 0)
        throw import_error_at_byte(file, 0, "not a marionette input log (bad magic)");
    header.version = get_u32(data + 8);
    if (header.version < kOldestInputLogVersion || header.version > kInputLogVersion)
        throw import_error_at_byte(file, 8, "unsupported input log version " + std::to_string(header.version) +
                                                " (this build reads versions " + std::to_string(kOldestInputLogVersion) +
                                                " to " + std::to_string(kInputLogVersion) + ")");
    header.tick_rate_hz = get_u32(data + 12);
    header.clip_data_hash = get_u64(data + 16);
    const std::uint32_t config_size = get_u32(data + 24);
    if (config_size > kMaxConfigBytes || config_size > size - kFixedHeaderSize - kCrcSize)
        throw import_error_at_byte(file, 24, "header's configuration length " + std::to_string(config_size) +
                                                 " exceeds the file");
    size_t header_end = kFixedHeaderSize + config_size;
    if (header.version >= 2) header_end = decode_header_texts(data, size, file, header_end, header);
    if (get_u32(data + header_end) != crc32_of(data, header_end))
        throw import_error_at_byte(file, static_cast<std::int64_t>(header_end), "header CRC mismatch: the header is corrupt");
    if (header.tick_rate_hz == 0 || header.tick_rate_hz > kMaxTickRateHz)
        throw import_error_at_byte(file, 12, "tick rate " + std::to_string(header.tick_rate_hz) + " Hz is out of range");
    header.config_text.assign(reinterpret_cast<const char*>(data + kFixedHeaderSize), config_size);
    return header_end + kCrcSize;
}

// Why decoding stops at a chunk (the log is replayed up to it); nullopt: the chunk is sound.
using ChunkDefect = std::optional<std::string>;

struct ChunkHeader {
    std::uint64_t first_tick = 0;
    std::uint32_t ticks = 0;
    std::uint32_t payload_size = 0;
};

// The chunk header at `pos`, checked against the file's size, its CRC (which
// covers the payload too) and the tick the log has reached.
ChunkDefect read_chunk_header(const std::uint8_t* data, size_t size, size_t pos, std::uint64_t next_tick, ChunkHeader& out) {
    if (size - pos < kChunkHeaderSize) return "incomplete chunk header";
    const std::uint8_t* chunk = data + pos;
    if (std::memcmp(chunk, kChunkMagic, 4) != 0) return "bad chunk magic";
    out.first_tick = get_u64(chunk + 4);
    out.ticks = get_u32(chunk + 12);
    out.payload_size = get_u32(chunk + 16);
    const std::uint32_t crc = get_u32(chunk + 20);
    if (out.ticks > kMaxChunkTicks)
        return "chunk claims " + std::to_string(out.ticks) + " ticks, more than a chunk may hold";
    if (out.payload_size > kMaxChunkPayload || out.payload_size > size - pos - kChunkHeaderSize)
        return "chunk payload of " + std::to_string(out.payload_size) + " bytes runs past the end of the file";
    std::uint32_t expect = crc32_of(chunk + 4, 16);
    expect = crc32_of(chunk + kChunkHeaderSize, out.payload_size, expect);
    if (expect != crc) return "chunk CRC mismatch";
    if (out.first_tick != next_tick)
        return "chunk starts at tick " + std::to_string(out.first_tick) + ", expected " + std::to_string(next_tick);
    return std::nullopt;
}

bool in_range(std::int64_t v, std::int64_t lo, std::int64_t hi) { return v >= lo && v <= hi; }

// Whether every field fits its TickInput member (fields_of's order).
bool fields_in_range(const std::int64_t (&f)[kFieldCount]) {
    constexpr std::int64_t kAxisMin = std::numeric_limits<std::int16_t>::min();
    constexpr std::int64_t kAxisMax = std::numeric_limits<std::int16_t>::max();
    constexpr std::int64_t kTriggerMax = std::numeric_limits<std::uint16_t>::max();
    constexpr std::int64_t kButtonsMax = std::numeric_limits<std::uint32_t>::max();
    return in_range(f[0], kAxisMin, kAxisMax) && in_range(f[1], kAxisMin, kAxisMax) && in_range(f[2], kAxisMin, kAxisMax) &&
           in_range(f[3], kAxisMin, kAxisMax) && in_range(f[4], 0, kTriggerMax) && in_range(f[5], 0, kTriggerMax) &&
           in_range(f[6], 0, kButtonsMax);
}

// fields_of's inverse (the fields are in range).
TickInput tick_input_of(const std::int64_t (&f)[kFieldCount]) {
    TickInput input;
    input.left_x = static_cast<std::int16_t>(f[0]);
    input.left_y = static_cast<std::int16_t>(f[1]);
    input.right_x = static_cast<std::int16_t>(f[2]);
    input.right_y = static_cast<std::int16_t>(f[3]);
    input.left_trigger = static_cast<std::uint16_t>(f[4]);
    input.right_trigger = static_cast<std::uint16_t>(f[5]);
    input.buttons = static_cast<std::uint32_t>(f[6]);
    return input;
}

// What one chunk holds, kept apart from the log until the whole chunk decodes.
struct DecodedChunk {
    std::vector<TickInput> ticks;
    std::vector<InputLogConfigChange> config_changes;
    std::vector<InputLogCheckpoint> checkpoints;
    bool complete = false;  // it holds the end marker
};

// A tick record after its tag: a zigzag delta for each field whose tag bit is
// set, then how many ticks (at least one, at most `ticks_left`) repeat the input.
ChunkDefect decode_tick_record(std::uint8_t tag, Reader& r, std::int64_t (&fields)[kFieldCount], std::uint64_t ticks_left,
                               DecodedChunk& out) {
    for (int i = 0; i < kFieldCount; ++i) {
        if (!(tag & (1u << i))) continue;
        std::uint64_t z = 0;
        if (!r.varint(z)) return "truncated field value";
        // Fields stay in range between records, so a delta beyond 2^32 can
        // only be corrupt (and would overflow the sum).
        const std::int64_t delta = unzigzag(z);
        if (delta < -kMaxFieldDelta || delta > kMaxFieldDelta)
            return std::string(kFieldNames[i]) + " changes by " + std::to_string(delta) + " at payload byte " +
                   std::to_string(r.pos) + ", more than any input value can";
        fields[i] += delta;
    }
    std::uint64_t repeat = 0;
    if (!r.varint(repeat) || repeat == 0) return "bad repeat count";
    if (repeat > ticks_left) return "more ticks than the chunk header states";
    if (!fields_in_range(fields)) return "input value out of range";
    out.ticks.insert(out.ticks.end(), static_cast<size_t>(repeat), tick_input_of(fields));
    return std::nullopt;
}

// A configuration-change record after its tag: the text's length, then the text.
ChunkDefect decode_config_change(Reader& r, std::uint64_t before_tick, DecodedChunk& out) {
    std::uint64_t len = 0;
    if (!r.varint(len) || len > kMaxConfigBytes || len > r.size - r.pos) return "bad configuration-change length";
    InputLogConfigChange change;
    change.before_tick = before_tick;
    change.config_text.assign(reinterpret_cast<const char*>(r.data + r.pos), static_cast<size_t>(len));
    r.pos += static_cast<size_t>(len);
    out.config_changes.push_back(std::move(change));
    return std::nullopt;
}

// A checkpoint record after its tag (version 2): the state hash after every tick before it.
ChunkDefect decode_checkpoint(Reader& r, std::uint64_t after_ticks, DecodedChunk& out) {
    if (r.size - r.pos < 8) return "truncated checkpoint";
    out.checkpoints.push_back({after_ticks, get_u64(r.data + r.pos)});
    r.pos += 8;
    return std::nullopt;
}

// A chunk's records (tick records, configuration changes, checkpoints, the end
// marker), whose ticks must add up to what its header states.
ChunkDefect decode_chunk_payload(const std::uint8_t* payload, const ChunkHeader& header, std::uint32_t version,
                                 DecodedChunk& out) {
    Reader r{payload, header.payload_size};
    std::int64_t fields[kFieldCount] = {0, 0, 0, 0, 0, 0, 0};  // the delta base starts at zero in each chunk
    while (r.pos < r.size) {
        const std::uint8_t tag = payload[r.pos++];
        ChunkDefect defect;
        if (out.complete) defect = "data after the end marker";
        else if (tag < kTickRecordTagLimit) defect = decode_tick_record(tag, r, fields, header.ticks - out.ticks.size(), out);
        else if (tag == kTagConfigChange) defect = decode_config_change(r, header.first_tick + out.ticks.size(), out);
        else if (tag == kTagCheckpoint && version >= 2) defect = decode_checkpoint(r, header.first_tick + out.ticks.size(), out);
        else if (tag == kTagEnd) out.complete = true;
        else defect = "unknown record tag " + std::to_string(tag);
        if (defect) return defect;
    }
    if (out.ticks.size() != header.ticks) return "chunk holds fewer ticks than its header states";
    return std::nullopt;
}

}  // namespace

DecodedInputLog decode_input_log(const std::vector<std::uint8_t>& bytes, const std::string& file) {
    DecodedInputLog log;
    const size_t size = bytes.size();
    const std::uint8_t* data = bytes.data();
    size_t pos = decode_header(data, size, file, log.header);
    log.good_bytes = static_cast<std::int64_t>(pos);
    while (pos < size) {
        ChunkHeader header;
        DecodedChunk chunk;
        ChunkDefect defect = log.complete ? ChunkDefect("data after the end marker")
                                          : read_chunk_header(data, size, pos, log.ticks.size(), header);
        if (!defect) defect = decode_chunk_payload(data + pos + kChunkHeaderSize, header, log.header.version, chunk);
        if (defect) {
            log.warning = file + ": input log truncated or corrupt at byte " + std::to_string(pos) + ": " + *defect +
                          "; replaying the " + std::to_string(log.ticks.size()) + " ticks before it";
            break;
        }
        log.ticks.insert(log.ticks.end(), chunk.ticks.begin(), chunk.ticks.end());
        for (InputLogConfigChange& change : chunk.config_changes) log.config_changes.push_back(std::move(change));
        log.checkpoints.insert(log.checkpoints.end(), chunk.checkpoints.begin(), chunk.checkpoints.end());
        log.complete = chunk.complete;
        pos += kChunkHeaderSize + header.payload_size;
        log.good_bytes = static_cast<std::int64_t>(pos);
    }
    if (log.warning.empty() && !log.complete)
        log.warning = file + ": input log has no end marker (the recording was interrupted); replaying all " +
                      std::to_string(log.ticks.size()) + " ticks it holds";
    return log;
}

}  // namespace marionette
