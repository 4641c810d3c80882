#pragma once
// Helpers shared by the test programs.
#include <string>
#include <vector>

namespace marionette::test {

// The shared motion-capture folder: $MARIONETTE_MOCAP_DIR, else ../shared/data/mocap
// beside the source tree. Empty when it does not exist; under CI=true a missing
// folder fails the calling test instead (CI always has it).
std::string mocap_dir();

// Whole file as text; fails the calling test if it cannot be read.
std::string read_text_file(const std::string& path);

// Path of a file under the source tree.
std::string source_path(const std::string& relative);

// The reproducers kept for fuzz target `target` (tests/data/fuzz_regressions/
// <target>/*, sorted); fails the calling test when the folder is missing or empty.
std::vector<std::string> fuzz_regression_files(const std::string& target);

}  // namespace marionette::test
