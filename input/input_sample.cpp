#include "input/input_sample.hpp"

#include <algorithm>

namespace marionette::input {

TimedInput to_timed_input(const InputSample& s) {
    TimedInput out;
    out.timestamp_ns = s.t_ns;
    out.input.left_x = quantize_stick(s.lx);
    out.input.left_y = quantize_stick(s.ly);
    out.input.right_x = quantize_stick(s.rx);
    out.input.right_y = quantize_stick(s.ry);
    out.input.left_trigger = quantize_trigger(s.lt);
    out.input.right_trigger = quantize_trigger(s.rt);
    out.input.buttons = s.buttons;
    return out;
}

std::string button_list_json(std::uint32_t buttons) {
    std::string out = "[";
    bool first = true;
    for (int i = 0; i < kButtonCount; ++i) {
        if (!(buttons & (1u << i))) continue;
        if (!first) out += ',';
        first = false;
        out += '"';
        out += kButtonNames[static_cast<std::size_t>(i)];
        out += '"';
    }
    return out + "]";
}

float normalise_centred(std::int32_t value, std::int32_t min, std::int32_t max) {
    if (max <= min) return 0.0f;
    const std::int64_t centre = static_cast<std::int64_t>(min) + (static_cast<std::int64_t>(max) - min + 1) / 2;
    const std::int64_t v = std::clamp<std::int64_t>(value, min, max);
    const std::int64_t span = v >= centre ? max - centre : centre - min;
    if (span <= 0) return 0.0f;
    return static_cast<float>(static_cast<double>(v - centre) / static_cast<double>(span));
}

float normalise_trigger(std::int32_t value, std::int32_t min, std::int32_t max) {
    if (max <= min) return 0.0f;
    const std::int64_t v = std::clamp<std::int64_t>(value, min, max);
    return static_cast<float>(static_cast<double>(v - min) / (static_cast<double>(max) - min));
}

}  // namespace marionette::input
