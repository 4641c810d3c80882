#pragma once
// Checks that a configuration text is refused with a ConfigError naming the file
// ("user.toml"), the line, the key and a message fragment. Shared by the config
// tests of each table.
#include <catch2/catch.hpp>

#include <string>

#include "app/config.hpp"

namespace marionette::test {

inline void expect_config_error(const std::string& text, int line, const std::string& key, const std::string& message) {
    INFO(text);
    try {
        apply_config_text(default_config(), text, "user.toml");
        FAIL("no error");
    } catch (const ConfigError& e) {
        CHECK(e.file() == "user.toml");
        CHECK(e.line() == line);
        CHECK(e.key() == key);
        CHECK_THAT(e.what(), Catch::Contains(message));
    }
}

}  // namespace marionette::test
