#pragma once
// JSON output for --json: every command builds its object with these two helpers
// (strings escaped per RFC 8259, numbers printed so they read back exactly).
#include <fmt/format.h>

#include <string>
#include <string_view>

namespace marionette::json {

inline std::string quote(std::string_view s) {
    std::string out = "\"";
    for (const char ch : s) {
        const auto c = static_cast<unsigned char>(ch);
        switch (ch) {
            case '"': out += "\\\""; break;
            case '\\': out += "\\\\"; break;
            case '\n': out += "\\n"; break;
            case '\r': out += "\\r"; break;
            case '\t': out += "\\t"; break;
            default:
                if (c < 0x20) out += fmt::format("\\u{:04x}", c);
                else out += ch;
        }
    }
    return out + "\"";
}

// Finite numbers as shortest round-trip text; JSON has no NaN/inf, so null.
template <typename Number>
std::string number(Number v) {
    if constexpr (std::is_floating_point_v<Number>) {
        if (!(v == v) || v > std::numeric_limits<Number>::max() || v < -std::numeric_limits<Number>::max())
            return "null";
    }
    return fmt::format("{}", v);
}

}  // namespace marionette::json
