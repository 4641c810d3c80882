// ASF + AMC import: the input is "ASF text \0 AMC text" (split at the first NUL
// byte; no NUL: all ASF and an empty AMC).
#include <cstring>

#include "runtime/formats/asf_amc.hpp"
#include "tests/fuzz/fuzz_support.hpp"

using namespace marionette;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view all = fuzz::as_text(data, size);
    const std::size_t cut = all.find('\0');
    const std::string_view asf = all.substr(0, cut);
    const std::string_view amc = cut == std::string_view::npos ? std::string_view() : all.substr(cut + 1);
    try {
        const Clip clip = import_asf_amc(asf, "fuzz.asf", amc, "fuzz.amc");
        fuzz::fuzz_check(validate_clip(clip).ok(), "import_asf_amc returned an inconsistent clip");
    } catch (const ImportError&) {
    }
    return 0;
}
