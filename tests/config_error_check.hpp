#pragma once
// Checks that a TOML text is refused with a ConfigError naming the file, the
// line, the key and a message fragment. Shared by the config and terrain tests.
#include <catch2/catch.hpp>

#include <string>

#include "app/config/config.hpp"

namespace marionette::test {

// `parse(text, file)` must throw the ConfigError.
template <typename Parse>
void expect_config_error_from(Parse&& parse, const std::string& file, const std::string& text, int line,
                              const std::string& key, const std::string& message) {
    INFO(text);
    try {
        parse(text, file);
        FAIL("no error");
    } catch (const ConfigError& e) {
        CHECK(e.file() == file);
        CHECK(e.line() == line);
        CHECK(e.key() == key);
        CHECK_THAT(e.what(), Catch::Contains(message));
    }
}

// The main configuration, applied on top of the shipped defaults as "user.toml".
inline void expect_config_error(const std::string& text, int line, const std::string& key, const std::string& message) {
    expect_config_error_from([](const std::string& t, const std::string& f) { apply_config_text(default_config(), t, f); },
                             "user.toml", text, line, key, message);
}

}  // namespace marionette::test
