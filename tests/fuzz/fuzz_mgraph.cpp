// .mgraph decoding on raw bytes (the checksum makes most mutations stop at the
// header; fuzz_mgraph_hash goes behind it).
#include "runtime/errors/import_error.hpp"
#include "runtime/graph/motion_graph.hpp"
#include "tests/fuzz/fuzz_support.hpp"

using namespace marionette;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        const MotionGraph g = deserialize_motion_graph(std::span<const std::uint8_t>(data, size), "fuzz.mgraph");
        fuzz::fuzz_check(validate_motion_graph(g).ok(), "deserialize accepted an invalid graph");
    } catch (const ImportError&) {
    }
    try {
        (void)motion_graph_source_hash(std::span<const std::uint8_t>(data, size), "fuzz.mgraph");
    } catch (const ImportError&) {
    }
    return 0;
}
