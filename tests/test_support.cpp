#include "tests/test_support.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace marionette::test {

std::string mocap_dir() {
    const char* env = std::getenv("MARIONETTE_MOCAP_DIR");
    std::string dir = (env && *env) ? env : MARIONETTE_DEFAULT_MOCAP_DIR;
    if (std::filesystem::is_directory(dir)) return dir;
    const char* ci = std::getenv("CI");
    if (ci && std::string(ci) == "true") FAIL("CI=true but the mocap folder is missing: " << dir);
    WARN("mocap folder not found, skipping: " << dir);
    return {};
}

std::string read_text_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    REQUIRE(in.good());
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::string source_path(const std::string& relative) { return std::string(MARIONETTE_SOURCE_DIR) + "/" + relative; }

std::vector<std::string> fuzz_regression_files(const std::string& target) {
    const std::filesystem::path dir = source_path("tests/data/fuzz_regressions/" + target);
    REQUIRE(std::filesystem::is_directory(dir));
    std::vector<std::string> files;
    for (const auto& entry : std::filesystem::directory_iterator(dir))
        if (entry.is_regular_file()) files.push_back(entry.path().string());
    std::sort(files.begin(), files.end());
    REQUIRE(!files.empty());
    return files;
}

}  // namespace marionette::test
