#include "runtime/sim/tick_input.hpp"

#include <cmath>

namespace marionette {

std::int16_t quantize_stick(double value) {
    if (!(value == value)) return 0;  // NaN
    if (value > 1.0) value = 1.0;
    if (value < -1.0) value = -1.0;
    return static_cast<std::int16_t>(std::lround(value * kStickScale));
}

std::uint16_t quantize_trigger(double value) {
    if (!(value == value)) return 0;
    if (value > 1.0) value = 1.0;
    if (value < 0.0) value = 0.0;
    return static_cast<std::uint16_t>(std::lround(value * kTriggerScale));
}

}  // namespace marionette
