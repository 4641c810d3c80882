#include "input/hid/ds4.hpp"

namespace marionette::input::ds4 {

ParseStatus parse(std::span<const std::uint8_t> report, InputSample& out) {
    return parse_sony_report(report, kLayout, out);
}

}  // namespace marionette::input::ds4
