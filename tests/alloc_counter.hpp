#pragma once
// Heap allocations made so far by this test program (tests/alloc_counter.cpp
// replaces the global operator new). Compare two readings around the code that
// must not allocate.
#include <cstdint>

namespace marionette::test {
std::uint64_t allocation_count();
}  // namespace marionette::test
