// Simulation configuration TOML applied on top of the defaults: refusals are
// ConfigError; an accepted configuration serialises to text that applies back
// to the same serialisation.
#include "app/config/config.hpp"
#include "tests/fuzz/fuzz_support.hpp"

using namespace marionette;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const AppConfig base = default_config();
    AppConfig config;
    try {
        config = apply_config_text(base, fuzz::as_text(data, size), "fuzz.toml");
    } catch (const ConfigError&) {
        return 0;
    }
    const std::string text = serialize_config(config.sim);
    try {
        const AppConfig back = apply_config_text(base, text, "serialized.toml");
        fuzz::fuzz_check(serialize_config(back.sim) == text, "configuration does not survive serialisation");
    } catch (const ConfigError& e) {
        std::fprintf(stderr, "serialised configuration does not apply: %s\n", e.what());
        fuzz::fuzz_fail("serialize_config wrote text apply_config_text refuses");
    }
    return 0;
}
