#include "runtime/formats/input_log.hpp"

#include <zlib.h>

#include <cstring>

namespace marionette {

namespace {
constexpr unsigned char kChunkMagic[4] = {'C', 'H', 'N', 'K'};
constexpr size_t kChunkHeaderSize = 4 + 8 + 4 + 4 + 4;  // magic, first tick, ticks, payload size, crc
// Payload tags. 0x00–0x7F: a tick record whose low 7 bits say which fields changed.
constexpr std::uint8_t kTagConfigChange = 0x80;
constexpr std::uint8_t kTagEnd = 0x81;
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

DecodedInputLog decode_input_log(const std::vector<std::uint8_t>& bytes, const std::string& file) {
    DecodedInputLog log;
    const size_t size = bytes.size();
    const std::uint8_t* data = bytes.data();
    constexpr size_t kFixedHeader = 8 + 4 + 4 + 8 + 4;
    if (size < kFixedHeader + 4)
        throw import_error_at_byte(file, 0, "file is too short to be an input log (" + std::to_string(size) + " bytes)");
    if (std::memcmp(data, kInputLogMagic, 8) != 0)
        throw import_error_at_byte(file, 0, "not a marionette input log (bad magic)");
    log.header.version = get_u32(data + 8);
    if (log.header.version != kInputLogVersion)
        throw import_error_at_byte(file, 8, "unsupported input log version " + std::to_string(log.header.version) +
                                                " (this build reads version " + std::to_string(kInputLogVersion) + ")");
    log.header.tick_rate_hz = get_u32(data + 12);
    log.header.clip_data_hash = get_u64(data + 16);
    const std::uint32_t config_size = get_u32(data + 24);
    if (config_size > kMaxConfigBytes || config_size > size - kFixedHeader - 4)
        throw import_error_at_byte(file, 24, "header's configuration length " + std::to_string(config_size) +
                                                 " exceeds the file");
    const size_t header_end = kFixedHeader + config_size;
    if (get_u32(data + header_end) != crc32_of(data, header_end))
        throw import_error_at_byte(file, static_cast<std::int64_t>(header_end), "header CRC mismatch: the header is corrupt");
    if (log.header.tick_rate_hz == 0 || log.header.tick_rate_hz > 100000)
        throw import_error_at_byte(file, 12, "tick rate " + std::to_string(log.header.tick_rate_hz) + " Hz is out of range");
    log.header.config_text.assign(reinterpret_cast<const char*>(data + kFixedHeader), config_size);

    size_t pos = header_end + 4;
    log.good_bytes = static_cast<std::int64_t>(pos);
    auto stop = [&](size_t at, const std::string& why) {
        log.warning = file + ": input log truncated or corrupt at byte " + std::to_string(at) + ": " + why +
                      "; replaying the " + std::to_string(log.ticks.size()) + " ticks before it";
    };
    while (pos < size) {
        if (log.complete) {
            stop(pos, "data after the end marker");
            break;
        }
        if (size - pos < kChunkHeaderSize) {
            stop(pos, "incomplete chunk header");
            break;
        }
        const std::uint8_t* chunk = data + pos;
        if (std::memcmp(chunk, kChunkMagic, 4) != 0) {
            stop(pos, "bad chunk magic");
            break;
        }
        const std::uint64_t first_tick = get_u64(chunk + 4);
        const std::uint32_t ticks = get_u32(chunk + 12);
        const std::uint32_t payload_size = get_u32(chunk + 16);
        const std::uint32_t crc = get_u32(chunk + 20);
        if (ticks > kMaxChunkTicks) {
            stop(pos, "chunk claims " + std::to_string(ticks) + " ticks, more than a chunk may hold");
            break;
        }
        if (payload_size > kMaxChunkPayload || payload_size > size - pos - kChunkHeaderSize) {
            stop(pos, "chunk payload of " + std::to_string(payload_size) + " bytes runs past the end of the file");
            break;
        }
        const std::uint8_t* payload = chunk + kChunkHeaderSize;
        std::uint32_t expect = crc32_of(chunk + 4, 16);
        expect = crc32_of(payload, payload_size, expect);
        if (expect != crc) {
            stop(pos, "chunk CRC mismatch");
            break;
        }
        if (first_tick != log.ticks.size()) {
            stop(pos, "chunk starts at tick " + std::to_string(first_tick) + ", expected " + std::to_string(log.ticks.size()));
            break;
        }
        // Decode into a scratch list first, so a chunk that passes its CRC but is
        // internally inconsistent is dropped whole.
        std::vector<TickInput> chunk_ticks_decoded;
        std::vector<InputLogConfigChange> chunk_changes;
        std::uint64_t chunk_ticks = 0;
        bool chunk_complete = false;
        std::string error;
        Reader r{payload, payload_size};
        std::int64_t fields[kFieldCount] = {0, 0, 0, 0, 0, 0, 0};
        while (r.pos < r.size && error.empty()) {
            const std::uint8_t tag = payload[r.pos++];
            if (chunk_complete) {
                error = "data after the end marker";
            } else if (tag < 0x80) {
                for (int i = 0; i < kFieldCount && error.empty(); ++i) {
                    if (!(tag & (1u << i))) continue;
                    std::uint64_t z = 0;
                    if (!r.varint(z)) {
                        error = "truncated field value";
                    } else {
                        // Fields stay in range between records, so a delta beyond
                        // 2^32 can only be corrupt (and would overflow the sum).
                        const std::int64_t delta = unzigzag(z);
                        if (delta < -kMaxFieldDelta || delta > kMaxFieldDelta)
                            error = std::string(kFieldNames[i]) + " changes by " + std::to_string(delta) +
                                    " at payload byte " + std::to_string(r.pos) + ", more than any input value can";
                        else
                            fields[i] += delta;
                    }
                }
                std::uint64_t repeat = 0;
                if (error.empty() && (!r.varint(repeat) || repeat == 0)) error = "bad repeat count";
                if (error.empty() && repeat > ticks - chunk_ticks) error = "more ticks than the chunk header states";
                const bool axes_ok = fields[0] >= -32768 && fields[0] <= 32767 && fields[1] >= -32768 &&
                                     fields[1] <= 32767 && fields[2] >= -32768 && fields[2] <= 32767 &&
                                     fields[3] >= -32768 && fields[3] <= 32767;
                const bool rest_ok = fields[4] >= 0 && fields[4] <= 65535 && fields[5] >= 0 && fields[5] <= 65535 &&
                                     fields[6] >= 0 && fields[6] <= 0xffffffffll;
                if (error.empty() && !(axes_ok && rest_ok)) error = "input value out of range";
                if (!error.empty()) break;
                TickInput input;
                input.left_x = static_cast<std::int16_t>(fields[0]);
                input.left_y = static_cast<std::int16_t>(fields[1]);
                input.right_x = static_cast<std::int16_t>(fields[2]);
                input.right_y = static_cast<std::int16_t>(fields[3]);
                input.left_trigger = static_cast<std::uint16_t>(fields[4]);
                input.right_trigger = static_cast<std::uint16_t>(fields[5]);
                input.buttons = static_cast<std::uint32_t>(fields[6]);
                chunk_ticks_decoded.insert(chunk_ticks_decoded.end(), static_cast<size_t>(repeat), input);
                chunk_ticks += repeat;
            } else if (tag == kTagConfigChange) {
                std::uint64_t len = 0;
                if (!r.varint(len) || len > kMaxConfigBytes || len > r.size - r.pos) {
                    error = "bad configuration-change length";
                    break;
                }
                InputLogConfigChange change;
                change.before_tick = log.ticks.size() + chunk_ticks;
                change.config_text.assign(reinterpret_cast<const char*>(payload + r.pos), static_cast<size_t>(len));
                r.pos += static_cast<size_t>(len);
                chunk_changes.push_back(std::move(change));
            } else if (tag == kTagEnd) {
                chunk_complete = true;
            } else {
                error = "unknown record tag " + std::to_string(tag);
            }
        }
        if (error.empty() && chunk_ticks != ticks) error = "chunk holds fewer ticks than its header states";
        if (!error.empty()) {
            stop(pos, error);
            break;
        }
        log.ticks.insert(log.ticks.end(), chunk_ticks_decoded.begin(), chunk_ticks_decoded.end());
        for (InputLogConfigChange& change : chunk_changes) log.config_changes.push_back(std::move(change));
        log.complete = chunk_complete;
        pos += kChunkHeaderSize + payload_size;
        log.good_bytes = static_cast<std::int64_t>(pos);
    }
    if (log.warning.empty() && !log.complete)
        log.warning = file + ": input log has no end marker (the recording was interrupted); replaying all " +
                      std::to_string(log.ticks.size()) + " ticks it holds";
    return log;
}

}  // namespace marionette
