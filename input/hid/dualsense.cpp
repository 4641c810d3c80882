#include "input/hid/dualsense.hpp"

namespace marionette::input::dualsense {

ParseStatus parse(std::span<const std::uint8_t> report, InputSample& out) {
    return parse_sony_report(report, kLayout, out);
}

}  // namespace marionette::input::dualsense
