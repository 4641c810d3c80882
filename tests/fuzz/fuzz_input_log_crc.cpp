// Input log decoding behind the checksums: fix_up_input_log (fixups.hpp)
// rewrites the header CRC and every chunk's framing and CRC so that mutations
// reach the record decoder instead of dying at a CRC check. The raw target
// (fuzz_input_log) covers the checks this skips.
#include <vector>

#include "runtime/formats/input_log.hpp"
#include "tests/fuzz/fixups.hpp"
#include "tests/fuzz/fuzz_support.hpp"

using namespace marionette;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::vector<std::uint8_t> bytes(data, data + size);
    fuzz::fix_up_input_log(bytes);
    try {
        const DecodedInputLog log = decode_input_log(bytes, "fuzz.mlog");
        fuzz::fuzz_check(log.good_bytes >= 0 && static_cast<std::size_t>(log.good_bytes) <= size,
                         "good_bytes outside the file");
        // Whatever decoded must encode and decode back to the same ticks.
        const std::vector<std::uint8_t> again = encode_input_log(log.header, log.ticks, 60);
        const DecodedInputLog back = decode_input_log(again, "again.mlog");
        fuzz::fuzz_check(back.complete && back.ticks == log.ticks, "decoded ticks do not survive re-encoding");
    } catch (const ImportError&) {
    }
    return 0;
}
