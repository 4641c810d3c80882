// Reproducers found by the fuzz targets (tests/fuzz), kept as regular inputs:
// each one is refused cleanly, with a message that says where and what. The
// asan preset runs these under AddressSanitizer + UBSan, where the original bug
// (undefined behaviour) would abort.
#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <iterator>
#include <vector>

#include "runtime/formats/input_log.hpp"
#include "runtime/formats/stick_program.hpp"
#include "runtime/math/det_math.hpp"
#include "tests/fuzz/fixups.hpp"
#include "tests/test_support.hpp"

using namespace marionette;

namespace {
std::vector<std::uint8_t> read_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    REQUIRE(in.good());
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
}  // namespace

TEST_CASE("fuzz regressions: input logs with valid CRCs and crafted values are refused at their chunk") {
    for (const std::string& path : test::fuzz_regression_files("input_log_crc")) {
        INFO(path);
        std::vector<std::uint8_t> bytes = read_bytes(path);
        fuzz::fix_up_input_log(bytes);  // as fuzz_input_log_crc does before decoding
        DecodedInputLog log;
        REQUIRE_NOTHROW(log = decode_input_log(bytes, "repro.mlog"));
        // Every reproducer here is a corrupt chunk: decoding stops at it with a
        // warning naming the byte offset, keeping only the chunks before it.
        CHECK_FALSE(log.complete);
        CHECK_THAT(log.warning, Catch::Contains("repro.mlog: input log truncated or corrupt at byte "));
        CHECK(log.good_bytes < static_cast<std::int64_t>(bytes.size()));
    }
}

TEST_CASE("fuzz regressions: a tick-record delta that would overflow the field is refused, naming the field") {
    // Two records on left_x: +100, then +INT64_MAX (the sum overflowed a signed
    // 64-bit integer before the fix: UB that UBSan reported).
    const std::vector<std::uint8_t> bytes =
        read_bytes(test::source_path("tests/data/fuzz_regressions/input_log_crc/delta_overflow.mlog"));
    const DecodedInputLog log = decode_input_log(bytes, "delta_overflow.mlog");
    CHECK(log.ticks.empty());
    CHECK_FALSE(log.complete);
    CHECK_THAT(log.warning, Catch::Contains("at byte 32: left_x changes by 9223372036854775807 at payload byte "));
    CHECK_THAT(log.warning, Catch::Contains("more than any input value can; replaying the 0 ticks before it"));
    CHECK(log.good_bytes == 32);
}

// fuzz_stick_program: a circle segment with `from=7.7e77` degrees. det::sin_cos
// reduced such an angle coarsely, leaving the quadrant count far outside int64
// (undefined behaviour in the conversion). It now renders, every value in range.
TEST_CASE("fuzz regressions: a circle starting at an absurd angle renders within the stick range") {
    const std::string path = test::source_path("tests/data/fuzz_regressions/stick_program/huge_circle_angle.prog");
    std::ifstream in(path, std::ios::binary);
    REQUIRE(in.good());
    const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    const StickProgram program = parse_stick_program(text, path);
    REQUIRE(program.duration_s() <= 60.0);
    const std::vector<TickInput> ticks = render_stick_program(program, 240);
    REQUIRE(!ticks.empty());
    for (const TickInput& t : ticks) {
        CHECK(t.left_x >= -32767);
        CHECK(t.left_y >= -32767);
    }
    for (const double x : {1.0e7, -3.0e12, 1.0e22, 7.7e77 * det::kDegToRad, -1.0e300, 1.7976931348623157e308}) {
        double s = 2.0, c = 2.0;
        det::sin_cos(x, s, c);
        INFO(x);
        CHECK(std::abs(s) <= 1.0);
        CHECK(std::abs(c) <= 1.0);
        CHECK(std::abs(s * s + c * c - 1.0) < 1e-12);
    }
}
