// BVH import on arbitrary text: refusals are ImportError; an accepted clip is
// internally consistent.
#include "runtime/formats/bvh.hpp"
#include "tests/fuzz/fuzz_support.hpp"

using namespace marionette;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        const Clip clip = import_bvh(fuzz::as_text(data, size), "fuzz.bvh");
        fuzz::fuzz_check(validate_clip(clip).ok(), "import_bvh returned an inconsistent clip");
    } catch (const ImportError&) {
    }
    return 0;
}
