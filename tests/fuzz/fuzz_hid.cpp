// Every HID report parser. The first byte picks the parser (mod 5): 0 DualShock 4,
// 1 DualSense, 2 Switch Pro, 3 Steam Deck, 4 Switch Pro factory calibration
// block followed by a Switch Pro report parsed with that calibration. The rest
// is the report. An accepted report gives finite values in range.
#include <cmath>

#include "input/hid/hid_pad.hpp"
#include "input/hid/switch_pro.hpp"
#include "tests/fuzz/fuzz_support.hpp"

using namespace marionette;
using namespace marionette::input;

namespace {
void check_sample(const InputSample& s) {
    const float axes[] = {s.lx, s.ly, s.rx, s.ry};
    for (float a : axes) fuzz::fuzz_check(std::isfinite(a) && a >= -1.0f && a <= 1.0f, "stick outside [-1, 1]");
    fuzz::fuzz_check(std::isfinite(s.lt) && s.lt >= 0.0f && s.lt <= 1.0f, "left trigger outside [0, 1]");
    fuzz::fuzz_check(std::isfinite(s.rt) && s.rt >= 0.0f && s.rt <= 1.0f, "right trigger outside [0, 1]");
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 1) return 0;
    const int mode = data[0] % 5;
    std::span<const std::uint8_t> rest(data + 1, size - 1);
    switchpro::Calibration calibration = switchpro::kDefaultCalibration;
    HidFormat format = HidFormat::switchpro;
    if (mode == 4) {
        if (rest.size() < switchpro::kFactoryStickCalSize) return 0;
        (void)switchpro::decode_factory_calibration(rest.first(switchpro::kFactoryStickCalSize), calibration);
        rest = rest.subspan(switchpro::kFactoryStickCalSize);
    } else {
        format = static_cast<HidFormat>(mode);
    }
    InputSample sample;
    const ParseStatus status = parse_hid_report(format, rest, calibration, sample);
    if (status == ParseStatus::ok) check_sample(sample);
    return 0;
}
