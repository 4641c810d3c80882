#pragma once
// Configuration files: TOML, validated against one schema. The default file
// (config/marionette.toml, also compiled into the binary) states every key; a user
// file overrides only what it names. Errors name file, line, key and what was
// expected.
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "app/config/app_config.hpp"
#include "runtime/errors/parse_error.hpp"

namespace marionette {

// A configuration file's error: a ParseError whose subject is the key at fault
// ("table.key"; empty for the file as a whole).
class ConfigError : public ParseError {
public:
    ConfigError(std::string file, int line, std::string key, std::string message)
        : ParseError(std::move(file), line, -1, key, std::move(message)), key_(std::move(key)) {}
    const std::string& key() const { return key_; }

private:
    std::string key_;
};

struct ConfigKeyInfo {
    std::string table;
    std::string key;       // without the table
    std::string type;      // "integer", "float" or "string" (min and max unused)
    double min = 0.0;
    double max = 0.0;
    std::string doc;
    // A live edit reaches the tick: a SimConfig key that is not structural
    // (simulation.tick_rate_hz, [puppet]). False for keys read at start or by graph builds.
    bool live = false;
};

// Every key the configuration accepts, in the order the effective text lists them.
std::vector<ConfigKeyInfo> config_schema();

// A numeric key's value in `config` as the effective text writes it (floats in
// the shortest text that reads back to the same bits); nothing for an unknown
// or non-numeric key.
std::optional<std::string> config_value_text(const AppConfig& config, std::string_view table, std::string_view key);
// The same value as a number.
std::optional<double> config_number(const AppConfig& config, std::string_view table, std::string_view key);
// "auto", "gait", "graph", "graph_feet" or "matching", as [motion] source spells it.
std::string motion_source_name(MotionSourceSetting source);
// [timing] interpolation: "interpolate", "extrapolate" or "latest".
std::string interpolation_name(Interpolation mode);

// Applies the TOML text on top of `base`. Throws ConfigError.
AppConfig apply_config_text(const AppConfig& base, std::string_view toml_text, const std::string& file_name);

// The built-in default file's text and the configuration it gives.
std::string_view default_config_text();
AppConfig default_config();

// Defaults, then the user file (if the path is not empty). Throws ConfigError
// (a missing or unreadable file is one too).
AppConfig load_config(const std::string& user_file);

// The effective simulation configuration as TOML, keys in schema order, floats
// printed so they parse back to the same bits: every key the tick reads and no
// other ([realtime] and the graph build keys are not in it). Logs embed this text.
std::string serialize_config(const SimConfig& config);

// A log's embedded configuration (text written by serialize_config, or any
// complete or partial config) on top of the defaults, as replay reads it. Logs
// written before the tick's keys were split from the rest also carry [realtime]
// and the [motion_graph] build keys: still accepted, they land in the parts the
// tick never reads (a `--graph default` replay builds the default graph with them).
AppConfig config_from_text(std::string_view toml_text, const std::string& origin);

// A log's configuration change (or any TOML text) applied on top of the running
// simulation configuration; keys of the other parts are accepted and dropped.
SimConfig apply_config_change(const SimConfig& running, std::string_view toml_text, const std::string& origin);

}  // namespace marionette
