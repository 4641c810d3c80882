#include "input/hid/ds4.hpp"

#include "input/hid/sony_report.hpp"

namespace marionette::input::ds4 {

namespace {
constexpr SonyReportLayout kLayout{
    .usb_report_id = kUsbReportId, .usb_report_size = kUsbReportSize,
    .bt_report_id = kBtReportId, .bt_report_size = kBtReportSize, .bt_shift = kBtShift,
    .bt_crc_offset = kBtCrcOffset, .bt_crc_seed = kBtCrcSeed,
    .left_x = kLeftX, .left_y = kLeftY, .right_x = kRightX, .right_y = kRightY,
    .left_trigger = kLeftTrigger, .right_trigger = kRightTrigger,
    .buttons0 = kButtons0, .buttons1 = kButtons1, .buttons2 = kButtons2,
    .counter = kButtons2, .counter_shift = kCounterShift,
};
static_assert(kCross == kSonyCross && kShare == kSonyShare && kPs == kSonyPs && kHatMask == kSonyHatMask);
}  // namespace

ParseStatus parse(std::span<const std::uint8_t> report, InputSample& out) {
    return parse_sony_report(report, kLayout, out);
}

}  // namespace marionette::input::ds4
