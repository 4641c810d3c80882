#pragma once
// A fixed-seed generator for generated test cases: runtime/math/splitmix64.hpp
// with the draws the tests use.
#include <cstddef>
#include <cstdint>

#include "runtime/math/splitmix64.hpp"

namespace marionette::test {

struct SeededRandom {
    std::uint64_t state;
    std::uint64_t next() { return splitmix64_next(state); }
    double unit() { return splitmix64_unit(state); }  // [0, 1)
    double uniform(double lo, double hi) { return lo + (hi - lo) * unit(); }
    std::size_t below(std::size_t n) { return static_cast<std::size_t>(next() % n); }
};

}  // namespace marionette::test
