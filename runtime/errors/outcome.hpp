#pragma once
// The non-throwing result of a check, or of a setup step that may fail: ok, or
// one sentence saying what is wrong. It is the one way a function reports a
// problem without throwing (never an empty string meaning OK, never a bool plus
// an error out-parameter). Success holds an empty string, so returning it does
// not allocate.
#include <string>
#include <utility>

namespace marionette {

class [[nodiscard]] Outcome {
public:
    static Outcome success() { return Outcome(); }
    static Outcome failure(std::string problem) { return Outcome(std::move(problem)); }

    bool ok() const { return ok_; }
    // What is wrong; empty when ok().
    const std::string& problem() const { return problem_; }

private:
    Outcome() = default;
    explicit Outcome(std::string problem) : ok_(false), problem_(std::move(problem)) {}

    bool ok_ = true;
    std::string problem_;
};

}  // namespace marionette
