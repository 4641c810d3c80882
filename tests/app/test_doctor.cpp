#include <catch2/catch.hpp>

#include <cerrno>

#include "app/cli/doctor.hpp"

using namespace marionette::doctor;

namespace {
NodeAccess node(const std::string& group, unsigned mode) {
    NodeAccess n;
    n.path = "/dev/hidraw3";
    n.owner = "root";
    n.group = group;
    n.mode = mode;
    return n;
}
UserInfo user(std::vector<std::string> groups) {
    UserInfo u;
    u.name = "pat";
    u.groups = std::move(groups);
    return u;
}
const std::string kPad = "Sony DualSense 054c:0ce6";
}  // namespace

TEST_CASE("doctor: an unreadable pad is explained in one line naming the missing group, mode or rule", "[doctor]") {
    // The rule applied (group marionette) but the user is not in the group.
    std::string line = explain_unreadable(kPad, node("marionette", 0660), user({"pat", "audio"}), true, EACCES);
    CHECK(line.find('\n') == std::string::npos);
    CHECK(line.find("/dev/hidraw3 (Sony DualSense 054c:0ce6)") == 0);
    CHECK(line.find("owned root:marionette mode 0660") != std::string::npos);
    CHECK(line.find("usermod -aG marionette pat") != std::string::npos);

    // In the group, but the mode gives the group nothing.
    line = explain_unreadable(kPad, node("marionette", 0600), user({"pat", "marionette"}), true, EACCES);
    CHECK(line.find("the group may not read it") != std::string::npos);
    CHECK(line.find("udevadm control --reload-rules") != std::string::npos);

    // The rule is installed but the node still has the kernel's default owner.
    line = explain_unreadable(kPad, node("root", 0600), user({"pat"}), true, EACCES);
    CHECK(line.find("70-marionette.rules is installed but did not apply") != std::string::npos);

    // No rule at all.
    line = explain_unreadable(kPad, node("root", 0600), user({"pat"}), false, EACCES);
    CHECK(line.find("no udev rule for it: install 70-marionette.rules") != std::string::npos);
    CHECK(line.find('\n') == std::string::npos);

    // Not a permission problem: the errno's text.
    line = explain_unreadable(kPad, node("root", 0600), user({"pat"}), false, ENODEV);
    CHECK(line.find("cannot open: No such device") != std::string::npos);
}

TEST_CASE("doctor: problems decide the exit, warnings do not", "[doctor]") {
    DoctorReport r;
    r.user = user({"pat"});
    r.display.request = "auto";
    r.display.choice = "headless";
    r.realtime.allowed = false;
    r.memlock.allowed = true;
    r.recordings.dir = "/home/pat/.local/state/marionette/recordings";
    r.recordings.existing = "/home/pat";
    r.recordings.writable = true;
    r.recordings.free_bytes = 10ull << 30;
    classify(r);
    CHECK(r.problems.empty());
    REQUIRE(r.warnings.size() == 2);  // no pad; realtime refused
    CHECK(r.warnings[0].find("no pad visible") == 0);
    CHECK(r.warnings[1].find("realtime priority not allowed") == 0);
    CHECK(to_text(r).find("ok: marionette can run") != std::string::npos);
    CHECK(to_json(r).find("\"ok\":true") != std::string::npos);

    DoctorReport bad = r;
    bad.problems.clear();
    bad.warnings.clear();
    PadNode pad;
    pad.path = "/dev/hidraw3";
    pad.backend = "hidraw";
    pad.problem = "/dev/hidraw3 (x): not readable";
    bad.pads.push_back(pad);
    bad.display.request = "kms";
    bad.display.choice = "kms";
    bad.display.reason = "asked for by name; no usable KMS output: no /dev/dri/card*";
    bad.recordings.free_bytes = 1u << 20;
    ConfigCheck c;
    c.name = "marionette.toml";
    c.error = "u.toml:2: locomotion.max_speed: expected a number";
    bad.configs.push_back(c);
    classify(bad);
    REQUIRE(bad.problems.size() == 4);
    CHECK(bad.problems[0] == pad.problem);
    CHECK(bad.problems[1].find("--display kms would fail") != std::string::npos);
    CHECK(bad.problems[2].find("recordings: only 1 MiB free") == 0);
    CHECK(bad.problems[3] == "config: " + c.error);
    const std::string text = to_text(bad);
    CHECK(text.find("4 problems:") != std::string::npos);
    CHECK(text.find("ok:") == std::string::npos);
    CHECK(to_json(bad).find("\"ok\":false") != std::string::npos);
}
