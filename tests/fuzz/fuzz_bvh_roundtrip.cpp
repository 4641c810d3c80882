// BVH export -> import: whatever import_bvh accepts, export_bvh writes a file
// that imports back with the same skeleton size and frame count.
#include "runtime/formats/bvh.hpp"
#include "tests/fuzz/fuzz_support.hpp"

using namespace marionette;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    Clip clip;
    try {
        clip = import_bvh(fuzz::as_text(data, size), "fuzz.bvh");
    } catch (const ImportError&) {
        return 0;
    }
    // Keep one input's work bounded (the text grows ~100 bytes per joint-frame).
    if (static_cast<long long>(clip.frame_count) * clip.joint_count() > 20000) return 0;
    const std::string text = export_bvh(clip);
    try {
        const Clip back = import_bvh(text, "exported.bvh");
        fuzz::fuzz_check(back.joint_count() == clip.joint_count(), "round trip changed the joint count");
        fuzz::fuzz_check(back.frame_count == clip.frame_count, "round trip changed the frame count");
    } catch (const ImportError& e) {
        std::fprintf(stderr, "exported BVH does not import: %s\n", e.what());
        fuzz::fuzz_fail("export_bvh wrote a file import_bvh refuses");
    }
    return 0;
}
