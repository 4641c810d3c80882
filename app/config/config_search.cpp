#include "app/config/config_search.hpp"

#include <cstdlib>
#include <filesystem>

#ifndef MARIONETTE_SYSCONFDIR
#define MARIONETTE_SYSCONFDIR "/etc/marionette"
#endif

namespace marionette {

namespace {
std::string env(const char* name) {
    const char* v = std::getenv(name);
    return v != nullptr ? std::string(v) : std::string();
}

bool is_regular_file(const std::string& path) {
    std::error_code ec;
    return std::filesystem::is_regular_file(path, ec);
}
}  // namespace

ConfigSearchDirs config_search_dirs_from_environment() {
    ConfigSearchDirs dirs;
    // XDG Base Directory: a relative XDG_CONFIG_HOME is invalid and ignored.
    const std::string xdg = env("XDG_CONFIG_HOME");
    const std::string home = env("HOME");
    if (!xdg.empty() && xdg.front() == '/') dirs.user_dir = xdg + "/marionette";
    else if (!home.empty()) dirs.user_dir = home + "/.config/marionette";
    const std::string sys = env("MARIONETTE_SYSCONFDIR");
    dirs.system_dir = sys.empty() ? std::string(MARIONETTE_SYSCONFDIR) : sys;
    return dirs;
}

ConfigLookup find_config_file(const std::string& explicit_file, const std::string& name, const ConfigSearchDirs& dirs) {
    ConfigLookup lookup;
    if (!explicit_file.empty()) {
        lookup.file = explicit_file;
        lookup.origin = ConfigOrigin::command_line;
        lookup.searched.push_back(explicit_file);
        return lookup;
    }
    const std::pair<const std::string*, ConfigOrigin> candidates[] = {{&dirs.user_dir, ConfigOrigin::user},
                                                                      {&dirs.system_dir, ConfigOrigin::system}};
    for (const auto& [dir, origin] : candidates) {
        if (dir->empty()) continue;
        const std::string path = *dir + "/" + name;
        lookup.searched.push_back(path);
        if (is_regular_file(path)) {
            lookup.file = path;
            lookup.origin = origin;
            return lookup;
        }
    }
    return lookup;
}

const char* config_origin_name(ConfigOrigin origin) {
    switch (origin) {
        case ConfigOrigin::command_line: return "--config";
        case ConfigOrigin::user: return "user";
        case ConfigOrigin::system: return "system";
        case ConfigOrigin::built_in: return "built-in";
    }
    return "?";
}

std::string describe_config_lookup(const ConfigLookup& lookup) {
    if (!lookup.file.empty())
        return lookup.file + " (" + config_origin_name(lookup.origin) + ") over the built-in defaults";
    std::string text = "the built-in defaults";
    if (!lookup.searched.empty()) {
        text += " (no ";
        for (std::size_t i = 0; i < lookup.searched.size(); ++i) text += (i ? ", " : "") + lookup.searched[i];
        text += ")";
    }
    return text;
}

}  // namespace marionette
