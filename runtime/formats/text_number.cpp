#include "runtime/formats/text_number.hpp"

#include <charconv>
#include <cmath>
#include <system_error>

namespace marionette {

namespace {
bool is_digit(char c) { return c >= '0' && c <= '9'; }
}  // namespace

NumberStatus parse_real(std::string_view token, double& out) {
    const char* first = token.data();
    const char* last = token.data() + token.size();
    if (last - first > 1 && *first == '+' && (first[1] == '.' || is_digit(first[1]))) ++first;
    double value = 0.0;
    const auto result = std::from_chars(first, last, value, std::chars_format::general);
    if (result.ec == std::errc::result_out_of_range && result.ptr == last) return NumberStatus::too_large;
    if (result.ec != std::errc() || result.ptr != last) return NumberStatus::not_a_number;
    if (!std::isfinite(value)) return NumberStatus::not_finite;
    if (value > kMaxTextNumber || value < -kMaxTextNumber) return NumberStatus::too_large;
    out = value;
    return NumberStatus::ok;
}

bool parse_integer(std::string_view token, std::int64_t& out) {
    const char* first = token.data();
    const char* last = token.data() + token.size();
    if (last - first > 1 && *first == '+' && is_digit(first[1])) ++first;
    std::int64_t value = 0;
    const auto result = std::from_chars(first, last, value);
    if (result.ec != std::errc() || result.ptr != last) return false;
    out = value;
    return true;
}

}  // namespace marionette
