#include "input/hid/dualsense.hpp"

#include "input/hid/sony_report.hpp"

namespace marionette::input::dualsense {

namespace {
constexpr SonyReportLayout kLayout{
    .usb_report_id = kUsbReportId, .usb_report_size = kUsbReportSize,
    .bt_report_id = kBtReportId, .bt_report_size = kBtReportSize, .bt_shift = kBtShift,
    .bt_crc_offset = kBtCrcOffset, .bt_crc_seed = kBtCrcSeed,
    .left_x = kLeftX, .left_y = kLeftY, .right_x = kRightX, .right_y = kRightY,
    .left_trigger = kLeftTrigger, .right_trigger = kRightTrigger,
    .buttons0 = kButtons0, .buttons1 = kButtons1, .buttons2 = kButtons2,
    .counter = kSequence, .counter_shift = 0,
};
static_assert(kCross == kSonyCross && kCreate == kSonyShare && kPs == kSonyPs && kHatMask == kSonyHatMask);
}  // namespace

ParseStatus parse(std::span<const std::uint8_t> report, InputSample& out) {
    return parse_sony_report(report, kLayout, out);
}

}  // namespace marionette::input::dualsense
