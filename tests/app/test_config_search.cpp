#include <catch2/catch.hpp>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "app/config/config_search.hpp"

using namespace marionette;

namespace {
struct TempTree {
    std::filesystem::path root;
    TempTree() {
        root = std::filesystem::temp_directory_path() /
               ("marionette-config-search-" + std::to_string(::getpid()) + "-" + std::to_string(counter()++));
        std::filesystem::create_directories(root / "user");
        std::filesystem::create_directories(root / "etc");
    }
    ~TempTree() {
        std::error_code ec;
        std::filesystem::remove_all(root, ec);
    }
    static int& counter() {
        static int n = 0;
        return n;
    }
    void write(const std::string& relative) const { std::ofstream(root / relative) << "# test\n"; }
    ConfigSearchDirs dirs() const { return {(root / "user").string(), (root / "etc").string()}; }
};
}  // namespace

TEST_CASE("config search: --config, then the user's, then the system's, then the built-in defaults", "[config]") {
    TempTree t;
    const ConfigSearchDirs dirs = t.dirs();
    ConfigLookup l = find_config_file("", "marionette.toml", dirs);
    CHECK(l.file.empty());
    CHECK(l.origin == ConfigOrigin::built_in);
    REQUIRE(l.searched.size() == 2);
    CHECK(l.searched[0] == dirs.user_dir + "/marionette.toml");
    CHECK(l.searched[1] == dirs.system_dir + "/marionette.toml");
    CHECK(describe_config_lookup(l) == "the built-in defaults (no " + l.searched[0] + ", " + l.searched[1] + ")");

    t.write("etc/marionette.toml");
    l = find_config_file("", "marionette.toml", dirs);
    CHECK(l.file == dirs.system_dir + "/marionette.toml");
    CHECK(l.origin == ConfigOrigin::system);
    CHECK(describe_config_lookup(l) == l.file + " (system) over the built-in defaults");

    t.write("user/marionette.toml");
    l = find_config_file("", "marionette.toml", dirs);
    CHECK(l.file == dirs.user_dir + "/marionette.toml");
    CHECK(l.origin == ConfigOrigin::user);
    CHECK(l.searched.size() == 1);  // the system directory was not looked at

    l = find_config_file("/somewhere/given.toml", "marionette.toml", dirs);
    CHECK(l.file == "/somewhere/given.toml");
    CHECK(l.origin == ConfigOrigin::command_line);
    CHECK(describe_config_lookup(l) == "/somewhere/given.toml (--config) over the built-in defaults");

    // Other names are looked up independently; a directory of that name is not a file.
    std::filesystem::create_directories(t.root / "user" / "render.toml");
    l = find_config_file("", "render.toml", dirs);
    CHECK(l.file.empty());
    t.write("etc/render.toml");
    CHECK(find_config_file("", "render.toml", dirs).origin == ConfigOrigin::system);
}

TEST_CASE("config search: XDG_CONFIG_HOME, else ~/.config, MARIONETTE_SYSCONFDIR overrides the system directory",
          "[config]") {
    struct Env {
        std::string name;
        std::string saved;
        bool had;
        explicit Env(const char* n) : name(n), had(std::getenv(n) != nullptr) {
            if (had) saved = std::getenv(n);
        }
        ~Env() {
            if (had) ::setenv(name.c_str(), saved.c_str(), 1);
            else ::unsetenv(name.c_str());
        }
    } xdg("XDG_CONFIG_HOME"), home("HOME"), sys("MARIONETTE_SYSCONFDIR");
    ::setenv("HOME", "/home/pat", 1);
    ::setenv("XDG_CONFIG_HOME", "/xdg", 1);
    ::unsetenv("MARIONETTE_SYSCONFDIR");
    ConfigSearchDirs d = config_search_dirs_from_environment();
    CHECK(d.user_dir == "/xdg/marionette");
    // The install's sysconfdir: /etc/marionette for the package's /usr prefix, /usr/local/etc/marionette by default.
    CHECK((d.system_dir == "/etc/marionette" || d.system_dir == "/usr/local/etc/marionette"));
    ::setenv("XDG_CONFIG_HOME", "relative/ignored", 1);  // the XDG spec: relative paths are invalid
    CHECK(config_search_dirs_from_environment().user_dir == "/home/pat/.config/marionette");
    ::unsetenv("XDG_CONFIG_HOME");
    CHECK(config_search_dirs_from_environment().user_dir == "/home/pat/.config/marionette");
    ::setenv("MARIONETTE_SYSCONFDIR", "/opt/etc/marionette", 1);
    CHECK(config_search_dirs_from_environment().system_dir == "/opt/etc/marionette");
}
