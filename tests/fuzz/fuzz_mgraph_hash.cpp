// .mgraph decoding behind the checksum: the harness rewrites the magic, version,
// flags, payload size and payload xxHash64, so mutations reach the payload
// reader. An accepted graph validates, and its serialisation reads back to itself.
#include <vector>

#include "runtime/errors/import_error.hpp"
#include "runtime/graph/motion_graph.hpp"
#include "tests/fuzz/fixups.hpp"
#include "tests/fuzz/fuzz_support.hpp"

using namespace marionette;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::vector<std::uint8_t> bytes(data, data + size);
    if (!fuzz::fix_up_mgraph(bytes)) return 0;
    try {
        const MotionGraph g = deserialize_motion_graph(bytes, "fuzz.mgraph");
        fuzz::fuzz_check(validate_motion_graph(g).ok(), "deserialize accepted an invalid graph");
        // The bytes need not be canonical (any non-zero byte is a true flag), but
        // what serialize writes reads back to the same graph, byte for byte.
        const std::vector<std::uint8_t> once = serialize_motion_graph(g);
        try {
            fuzz::fuzz_check(serialize_motion_graph(deserialize_motion_graph(once, "again.mgraph")) == once,
                             "a serialised graph does not read back to the same bytes");
        } catch (const ImportError& e) {
            std::fprintf(stderr, "serialised graph does not read back: %s\n", e.what());
            fuzz::fuzz_fail("serialize_motion_graph wrote bytes deserialize refuses");
        }
    } catch (const ImportError&) {
    }
    return 0;
}
