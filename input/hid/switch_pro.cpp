#include "input/hid/switch_pro.hpp"

#include <algorithm>

namespace marionette::input::switchpro {

namespace {
// Two 12-bit values packed in three bytes: a = low 12 bits, b = high 12 bits.
void unpack12(std::span<const std::uint8_t> b, std::size_t at, std::int32_t& lo, std::int32_t& hi) {
    lo = b[at] | ((b[at + 1] & 0x0F) << 8);
    hi = (b[at + 1] >> 4) | (b[at + 2] << 4);
}
void pack12(std::uint8_t* out, std::int32_t lo, std::int32_t hi) {
    out[0] = static_cast<std::uint8_t>(lo & 0xFF);
    out[1] = static_cast<std::uint8_t>(((lo >> 8) & 0x0F) | ((hi & 0x0F) << 4));
    out[2] = static_cast<std::uint8_t>((hi >> 4) & 0xFF);
}
float normalise(std::int32_t raw, std::int32_t centre, std::int32_t below, std::int32_t above) {
    const std::int32_t d = raw - centre;
    const double v = d >= 0 ? static_cast<double>(d) / above : static_cast<double>(d) / below;
    return static_cast<float>(std::clamp(v, -1.0, 1.0));
}
bool plausible(const StickCalibration& s) {
    return s.x_below > 0 && s.x_above > 0 && s.y_below > 0 && s.y_above > 0 && s.centre_x > 0 && s.centre_y > 0 &&
           s.centre_x < 4095 && s.centre_y < 4095;
}
}  // namespace

bool decode_factory_calibration(std::span<const std::uint8_t> block, Calibration& out) {
    if (block.size() < kFactoryStickCalSize) return false;
    const bool left_blank = std::all_of(block.begin(), block.begin() + 9, [](std::uint8_t b) { return b == 0xFF; });
    const bool right_blank = std::all_of(block.begin() + 9, block.begin() + 18, [](std::uint8_t b) { return b == 0xFF; });
    if (left_blank || right_blank) return false;
    Calibration cal;
    // Left stick: above-centre ranges, centre, below-centre ranges.
    unpack12(block, 0, cal.left.x_above, cal.left.y_above);
    unpack12(block, 3, cal.left.centre_x, cal.left.centre_y);
    unpack12(block, 6, cal.left.x_below, cal.left.y_below);
    // Right stick: centre, below-centre ranges, above-centre ranges.
    unpack12(block, 9, cal.right.centre_x, cal.right.centre_y);
    unpack12(block, 12, cal.right.x_below, cal.right.y_below);
    unpack12(block, 15, cal.right.x_above, cal.right.y_above);
    if (!plausible(cal.left) || !plausible(cal.right)) return false;
    cal.from_device = true;
    out = cal;
    return true;
}

std::array<std::uint8_t, kFactoryStickCalSize> encode_factory_calibration(const Calibration& c) {
    std::array<std::uint8_t, kFactoryStickCalSize> b{};
    pack12(&b[0], c.left.x_above, c.left.y_above);
    pack12(&b[3], c.left.centre_x, c.left.centre_y);
    pack12(&b[6], c.left.x_below, c.left.y_below);
    pack12(&b[9], c.right.centre_x, c.right.centre_y);
    pack12(&b[12], c.right.x_below, c.right.y_below);
    pack12(&b[15], c.right.x_above, c.right.y_above);
    return b;
}

std::array<std::uint8_t, kOutputReportSize> make_subcommand(std::uint8_t counter, std::uint8_t subcommand,
                                                            std::span<const std::uint8_t> args) {
    std::array<std::uint8_t, kOutputReportSize> out{};
    out[0] = kOutputSubcommand;
    out[1] = counter & 0x0F;
    // Neutral rumble for both motors (bytes 2-9).
    static constexpr std::uint8_t kRumbleNeutral[8] = {0x00, 0x01, 0x40, 0x40, 0x00, 0x01, 0x40, 0x40};
    std::copy(std::begin(kRumbleNeutral), std::end(kRumbleNeutral), out.begin() + 2);
    out[10] = subcommand;
    const std::size_t n = std::min(args.size(), out.size() - 11);
    std::copy_n(args.begin(), n, out.begin() + 11);
    return out;
}

ParseStatus parse(std::span<const std::uint8_t> r, const Calibration& cal, InputSample& out) {
    if (r.empty()) return ParseStatus::too_short;
    if (r[0] == kSubcommandReplyId || r[0] == kUsbReplyId) return ParseStatus::ignored;
    if (r[0] != kFullReportId) return ParseStatus::wrong_report_id;
    if (r.size() < kBtReportSize) return ParseStatus::too_short;
    if (r.size() != kBtReportSize && r.size() != kUsbReportSize)
        return r.size() > kUsbReportSize ? ParseStatus::too_long : ParseStatus::garbled;
    const std::uint8_t right = r[kButtonsRight], shared = r[kButtonsShared], left = r[kButtonsLeft];
    std::uint32_t buttons = 0;
    // Positional: B is the bottom face button, A the right one.
    if (right & kB) buttons |= button_bit(Button::south);
    if (right & kA) buttons |= button_bit(Button::east);
    if (right & kY) buttons |= button_bit(Button::west);
    if (right & kX) buttons |= button_bit(Button::north);
    if (left & kL) buttons |= button_bit(Button::left_shoulder);
    if (right & kR) buttons |= button_bit(Button::right_shoulder);
    if (shared & kMinus) buttons |= button_bit(Button::back);
    if (shared & kPlus) buttons |= button_bit(Button::start);
    if (shared & kHome) buttons |= button_bit(Button::guide);
    if (shared & kLStick) buttons |= button_bit(Button::left_stick);
    if (shared & kRStick) buttons |= button_bit(Button::right_stick);
    if (left & kUp) buttons |= button_bit(Button::dpad_up);
    if (left & kDown) buttons |= button_bit(Button::dpad_down);
    if (left & kLeft) buttons |= button_bit(Button::dpad_left);
    if (left & kRight) buttons |= button_bit(Button::dpad_right);

    std::int32_t x = 0, y = 0;
    unpack12(r, kLeftStick, x, y);
    out.lx = normalise(x, cal.left.centre_x, cal.left.x_below, cal.left.x_above);
    out.ly = normalise(y, cal.left.centre_y, cal.left.y_below, cal.left.y_above);
    unpack12(r, kRightStick, x, y);
    out.rx = normalise(x, cal.right.centre_x, cal.right.x_below, cal.right.x_above);
    out.ry = normalise(y, cal.right.centre_y, cal.right.y_below, cal.right.y_above);
    out.lt = (left & kZL) ? 1.0f : 0.0f;  // digital triggers
    out.rt = (right & kZR) ? 1.0f : 0.0f;
    out.buttons = buttons;
    out.has_device_counter = true;
    out.device_counter = r[kTimer];
    return ParseStatus::ok;
}

}  // namespace marionette::input::switchpro
