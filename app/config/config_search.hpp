#pragma once
// Where `run` (and `doctor`) find the configuration files (docs/deploy.md):
// the file given on the command line, else $XDG_CONFIG_HOME/marionette/NAME
// (~/.config/marionette/NAME when XDG_CONFIG_HOME is unset or relative), else
// the system directory (/etc/marionette/NAME in the package; overridable with
// MARIONETTE_SYSCONFDIR), else nothing: the built-in defaults. The search is a
// pure function of the directories so tests need no real /etc or home.
#include <string>
#include <vector>

namespace marionette {

struct ConfigSearchDirs {
    std::string user_dir;    // $XDG_CONFIG_HOME/marionette or ~/.config/marionette; empty: none
    std::string system_dir;  // /etc/marionette (the install's sysconfdir) or $MARIONETTE_SYSCONFDIR
};

// The directories for this process: environment, then the compiled-in default.
ConfigSearchDirs config_search_dirs_from_environment();

enum class ConfigOrigin { command_line, user, system, built_in };

struct ConfigLookup {
    std::string file;                    // empty: built-in defaults only
    ConfigOrigin origin = ConfigOrigin::built_in;
    std::vector<std::string> searched;   // every path looked at, in order
};

// `explicit_file` (from --config) wins without a look at the directories; else
// the first existing regular file named `name` in the user, then system directory.
ConfigLookup find_config_file(const std::string& explicit_file, const std::string& name, const ConfigSearchDirs& dirs);

// One phrase for the user: "/etc/marionette/marionette.toml (system) over the
// built-in defaults", or "the built-in defaults (none of ... exist)".
std::string describe_config_lookup(const ConfigLookup& lookup);
const char* config_origin_name(ConfigOrigin origin);  // "--config", "user", "system", "built-in"

}  // namespace marionette
