#pragma once
// Numbers in the text formats we import (BVH, ASF/AMC), read the same strict way
// everywhere: std::from_chars (locale-free, exact) plus a leading '+', which
// from_chars refuses but exporters write; nan, inf and magnitudes past
// kMaxTextNumber are refused so a corrupt file cannot feed them to the pose maths.
#include <cstdint>
#include <string_view>

namespace marionette {

inline constexpr double kMaxTextNumber = 1.0e9;

enum class NumberStatus { ok, not_a_number, not_finite, too_large };

// "1", "-.5", ".0083333", "1.0E1", "7.62852e-016", "+2".
NumberStatus parse_real(std::string_view token, double& out);

// A whole number ("+" allowed); false for anything else, including overflow.
bool parse_integer(std::string_view token, std::int64_t& out);

}  // namespace marionette
