#pragma once
// Configuration files: TOML, validated against one schema. The default file
// (config/marionette.toml, also compiled into the binary) states every key; a user
// file overrides only what it names. Errors name file, line, key and what was
// expected.
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/sim/sim_config.hpp"

namespace marionette {

class ConfigError : public std::runtime_error {
public:
    ConfigError(std::string file, int line, std::string key, std::string message)
        : std::runtime_error(file + (line > 0 ? ":" + std::to_string(line) : std::string()) +
                             (key.empty() ? std::string() : ": " + key) + ": " + message),
          file_(std::move(file)), line_(line), key_(std::move(key)) {}
    const std::string& file() const { return file_; }
    int line() const { return line_; }
    const std::string& key() const { return key_; }

private:
    std::string file_;
    int line_;
    std::string key_;
};

struct ConfigKeyInfo {
    std::string table;
    std::string key;       // without the table
    std::string type;      // "integer", "float" or "string" (min and max unused)
    double min = 0.0;
    double max = 0.0;
    std::string doc;
};

// Every key the configuration accepts, in the order the effective text lists them.
std::vector<ConfigKeyInfo> config_schema();

// "auto", "gait", "graph" or "graph_feet", as [motion] source spells it.
std::string motion_source_name(MotionSourceSetting source);

// Applies the TOML text on top of `base`. Throws ConfigError.
SimConfig apply_config_text(const SimConfig& base, std::string_view toml_text, const std::string& file_name);

// The built-in default file's text and the configuration it gives.
std::string_view default_config_text();
SimConfig default_config();

// Defaults, then the user file (if the path is not empty). Throws ConfigError
// (a missing or unreadable file is one too).
SimConfig load_config(const std::string& user_file);

// The complete effective configuration as TOML, keys in schema order, floats
// printed so they parse back to the same bits. Logs embed this text.
std::string serialize_config(const SimConfig& config);

// Parses text written by serialize_config (or any complete or partial config) on
// top of the defaults, as replay does with a log's embedded configuration.
SimConfig config_from_text(std::string_view toml_text, const std::string& origin);

}  // namespace marionette
