#pragma once
// Checksum fix-ups shared by the fuzz targets that go behind a checksum
// (fuzz_input_log_crc, fuzz_mgraph_hash) and the Catch2 tests that replay their
// reproducers (tests/data/fuzz_regressions/<target>/ holds the fuzzer's input as
// found; the test applies the same fix-up, so a reproducer is dropped in as is).
#include <xxhash.h>
#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <vector>

#include "runtime/formats/input_log.hpp"

namespace marionette::fuzz {

namespace detail {
inline void put_u32(std::uint8_t* p, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
inline void put_u64(std::uint8_t* p, std::uint64_t v) {
    for (int i = 0; i < 8; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
inline std::uint32_t get_u32(const std::uint8_t* p) {
    std::uint32_t v = 0;
    for (int i = 3; i >= 0; --i) v = (v << 8) | p[i];
    return v;
}
inline std::uint32_t crc(const std::uint8_t* p, std::size_t n, std::uint32_t seed = 0) {
    return static_cast<std::uint32_t>(::crc32(seed, p, static_cast<uInt>(n)));
}
}  // namespace detail

// Input log (docs/input-log.md): rewrites the magic, version (1 stays 1, any
// other value becomes the current version, so both header layouts are reached),
// the version 2 header texts' lengths, the header CRC and every chunk's magic,
// first-tick index and CRC. Chunk tick counts are capped at
// 4096 (a chunk may legally claim 2^24 ticks of 16 bytes each: memory by
// design, not a finding) and payload sizes at the bytes left.
inline void fix_up_input_log(std::vector<std::uint8_t>& b) {
    using namespace detail;
    constexpr std::size_t kFixed = 28;
    if (b.size() < kFixed + 4) return;
    std::memcpy(b.data(), kInputLogMagic, 8);
    const std::uint32_t version = get_u32(&b[8]) == 1 ? 1u : kInputLogVersion;
    put_u32(&b[8], version);
    std::uint32_t config = get_u32(&b[24]);
    if (config > b.size() - kFixed - 4) config = static_cast<std::uint32_t>(b.size() - kFixed - 4);
    put_u32(&b[24], config);
    std::size_t header_end = kFixed + config;
    for (int text = 0; version >= 2 && text < 2; ++text) {  // provenance, motion data
        if (b.size() - header_end < 8) {
            put_u32(&b[8], 1);  // no room for the version 2 texts: a version 1 header
            break;
        }
        std::uint32_t length = get_u32(&b[header_end]);
        if (length > b.size() - header_end - 8) length = static_cast<std::uint32_t>(b.size() - header_end - 8);
        put_u32(&b[header_end], length);
        header_end += 4 + length;
    }
    if (get_u32(&b[8]) == 1) header_end = kFixed + config;
    put_u32(&b[header_end], crc(b.data(), header_end));
    std::size_t pos = header_end + 4;
    std::uint64_t first_tick = 0;
    while (b.size() - pos >= 24) {
        std::uint8_t* c = &b[pos];
        std::memcpy(c, "CHNK", 4);
        put_u64(c + 4, first_tick);
        const std::uint32_t ticks = get_u32(c + 12) % 4097;
        put_u32(c + 12, ticks);
        std::uint32_t payload = get_u32(c + 16);
        if (payload > b.size() - pos - 24) payload = static_cast<std::uint32_t>(b.size() - pos - 24);
        put_u32(c + 16, payload);
        put_u32(c + 20, crc(c + 24, payload, crc(c + 4, 16)));
        first_tick += ticks;
        pos += 24 + payload;
    }
}

// .mgraph (docs/motion-graph.md): rewrites the magic, version, flags, payload
// size and payload xxHash64. False when the input is shorter than the header.
inline bool fix_up_mgraph(std::vector<std::uint8_t>& b) {
    using namespace detail;
    constexpr std::size_t kHeader = 40;
    if (b.size() < kHeader) return false;
    std::memcpy(b.data(), "MGRAPH\r\n", 8);
    put_u32(&b[8], 1);
    put_u32(&b[12], 0);
    put_u64(&b[24], b.size() - kHeader);
    put_u64(&b[32], XXH64(b.data() + kHeader, b.size() - kHeader, 0));
    return true;
}

}  // namespace marionette::fuzz
