// Input log decoding on raw bytes: a bad header is an ImportError, a bad chunk
// ends decoding with a warning; nothing else.
#include <vector>

#include "runtime/formats/input_log.hpp"
#include "tests/fuzz/fuzz_support.hpp"

using namespace marionette;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::vector<std::uint8_t> bytes(data, data + size);
    try {
        const DecodedInputLog log = decode_input_log(bytes, "fuzz.mlog");
        fuzz::fuzz_check(log.good_bytes >= 0 && static_cast<std::size_t>(log.good_bytes) <= size,
                         "good_bytes outside the file");
        fuzz::fuzz_check(log.complete || !log.warning.empty(), "an incomplete log without a warning");
    } catch (const ImportError&) {
    }
    return 0;
}
