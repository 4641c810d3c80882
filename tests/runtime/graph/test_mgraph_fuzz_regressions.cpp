// .mgraph reproducers found while fuzzing (tests/fuzz/fuzz_mgraph_hash): each is
// refused with an ImportError naming the file and what is wrong. Under the asan
// preset the original bug (signed overflow, UB) would abort here.
#include <catch2/catch.hpp>

#include <fstream>
#include <iterator>
#include <vector>

#include "runtime/errors/import_error.hpp"
#include "runtime/graph/motion_graph.hpp"
#include "tests/fuzz/fixups.hpp"
#include "tests/test_support.hpp"

using namespace marionette;

namespace {
std::vector<std::uint8_t> read_fixed_up(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    REQUIRE(in.good());
    std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    fuzz::fix_up_mgraph(bytes);  // as fuzz_mgraph_hash does before decoding
    return bytes;
}
}  // namespace

TEST_CASE("fuzz regressions: every kept .mgraph reproducer is refused with an ImportError") {
    for (const std::string& path : test::fuzz_regression_files("mgraph_hash")) {
        INFO(path);
        const std::vector<std::uint8_t> bytes = read_fixed_up(path);
        CHECK_THROWS_AS(deserialize_motion_graph(bytes, "repro.mgraph"), ImportError);
    }
}

TEST_CASE("fuzz regressions: a transition window of 2^31-1 frames is refused, not overflowed") {
    // The synthetic locomotion graph with k = 2147483647 and its first transition
    // edge 2147483647 frames long: frame 9 + k overflowed an int in validation.
    const std::vector<std::uint8_t> bytes =
        read_fixed_up(test::source_path("tests/data/fuzz_regressions/mgraph_hash/window_overflow.mgraph"));
    try {
        (void)deserialize_motion_graph(bytes, "window_overflow.mgraph");
        FAIL("the graph was accepted");
    } catch (const ImportError& e) {
        CHECK(e.file() == "window_overflow.mgraph");
        CHECK_THAT(e.message(), Catch::Contains("transition edge 1 runs past its clips"));
    }
}
