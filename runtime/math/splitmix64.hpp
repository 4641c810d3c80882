#pragma once
// splitmix64 (Steele, Lea, Flood 2014): a full-period 64-bit generator with one
// word of state. Integer arithmetic only, so a seed gives the same numbers on
// every platform, compiler and standard library (the std distributions do not):
// the graph's attract mode, the fault injector, generated sweep cases and test
// data all draw from it.
#include <cstdint>

namespace marionette {

inline std::uint64_t splitmix64_next(std::uint64_t& state) {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

// [0, 1) from the top 53 bits.
inline double splitmix64_unit(std::uint64_t& state) { return static_cast<double>(splitmix64_next(state) >> 11) * 0x1.0p-53; }

}  // namespace marionette
