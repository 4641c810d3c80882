// ASF skeleton import on arbitrary text.
#include "runtime/formats/asf_amc.hpp"
#include "tests/fuzz/fuzz_support.hpp"

using namespace marionette;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        const Skeleton skeleton = import_asf_skeleton(fuzz::as_text(data, size), "fuzz.asf");
        fuzz::fuzz_check(skeleton.joint_count() > 0, "import_asf_skeleton accepted a skeleton with no joints");
    } catch (const ImportError&) {
    }
    return 0;
}
