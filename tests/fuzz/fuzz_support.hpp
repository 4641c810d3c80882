#pragma once
// Shared helpers for the libFuzzer targets (tests/fuzz/README.md).
//
// A target calls the parser and swallows only the documented refusals (the
// parse-error family: ImportError for runtime files, ConfigError for TOML
// configuration). Anything else escaping — std::bad_alloc, std::out_of_range,
// a crash, UB, a leak — reaches libFuzzer and is a finding. A broken invariant
// on an accepted input is reported with fuzz_check (abort with a message).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

namespace marionette::fuzz {

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
    return {reinterpret_cast<const char*>(data), size};
}

[[noreturn]] inline void fuzz_fail(const char* what) {
    std::fprintf(stderr, "fuzz invariant broken: %s\n", what);
    std::abort();
}

inline void fuzz_check(bool ok, const char* what) {
    if (!ok) fuzz_fail(what);
}

inline void put_u32le(std::uint8_t* p, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
inline void put_u64le(std::uint8_t* p, std::uint64_t v) {
    for (int i = 0; i < 8; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
inline std::uint32_t get_u32le(const std::uint8_t* p) {
    std::uint32_t v = 0;
    for (int i = 3; i >= 0; --i) v = (v << 8) | p[i];
    return v;
}

}  // namespace marionette::fuzz
