// The error conventions (docs/architecture.md, "Errors"): one parse-error family
// whose what() says where and what, and Outcome for checks that do not throw.
#include <catch2/catch.hpp>

#include "runtime/errors/import_error.hpp"
#include "runtime/errors/outcome.hpp"
#include "runtime/errors/parse_error.hpp"

using namespace marionette;

TEST_CASE("an ImportError is a ParseError naming file and line, or file and byte", "[errors]") {
    const ImportError at_line("walk.bvh", 12, "expected a number");
    const ParseError& base = at_line;
    CHECK(std::string(base.what()) == "walk.bvh:12: expected a number");
    CHECK(base.file() == "walk.bvh");
    CHECK(base.line() == 12);
    CHECK(base.byte() == -1);
    CHECK(base.message() == "expected a number");

    const ImportError whole_file("walk.bvh", 0, "cannot open");
    CHECK(std::string(whole_file.what()) == "walk.bvh: cannot open");

    const ImportError at_byte = import_error_at_byte("run.mlog", 24, "bad length");
    CHECK(std::string(at_byte.what()) == "run.mlog: at byte 24: bad length");
    CHECK(at_byte.line() == 0);
    CHECK(at_byte.byte() == 24);
}

TEST_CASE("a ParseError with a subject names it between the place and the message", "[errors]") {
    const ParseError e("user.toml", 3, -1, "gait.step_height", "expected a number in [0, 1]");
    CHECK(std::string(e.what()) == "user.toml:3: gait.step_height: expected a number in [0, 1]");
    CHECK(e.message() == "expected a number in [0, 1]");
}

TEST_CASE("an Outcome is ok without a problem, or fails with one", "[errors]") {
    const Outcome ok = Outcome::success();
    CHECK(ok.ok());
    CHECK(ok.problem().empty());
    const Outcome failed = Outcome::failure("frame rate must be positive");
    CHECK_FALSE(failed.ok());
    CHECK(failed.problem() == "frame rate must be positive");
}
