#pragma once
// `marionette doctor`: what an operator checks before going live (docs/deploy.md).
// The probes (device nodes, display, limits, disk, config) fill a DoctorReport;
// the rules that turn facts into problems and one-line explanations are pure
// functions here so tests feed them described systems.
#include <cstdint>
#include <string>
#include <vector>

namespace marionette::doctor {

// A device node's ownership as stat() and the group database give it.
struct NodeAccess {
    std::string path;
    unsigned mode = 0;            // permission bits (0660 ...)
    std::string owner, group;     // names (numbers when the database has none)
};

// The user doctor runs as.
struct UserInfo {
    std::string name;
    std::vector<std::string> groups;  // names of the primary and supplementary groups
};

// One line: why `user` cannot read the node (open failed with `open_errno`) and
// the missing permission, group or rule. `description` names the pad.
std::string explain_unreadable(const std::string& description, const NodeAccess& node, const UserInfo& user,
                               bool udev_rule_installed, int open_errno);

struct PadNode {
    std::string path;             // /dev/hidrawN or /dev/input/eventN
    std::string backend;          // "hidraw" or "evdev"
    std::string name;
    std::uint16_t vendor_id = 0, product_id = 0;
    bool readable = false;
    std::string problem;          // empty when readable
    double report_rate_hz = -1;   // < 0: not measured
    std::uint64_t reports = 0;    // in the measuring window
};

struct DisplayCheck {
    std::string request = "auto"; // what was asked (--display)
    std::string choice;           // headless|window|kms: what run would take
    std::string reason;
    std::string kms_device, kms_connector, kms_mode;  // when kms: the card, connector and mode chosen
};

struct LimitCheck {
    bool allowed = false;
    bool capability = false;      // CAP_SYS_NICE / CAP_IPC_LOCK effective
    bool unlimited = false;
    std::uint64_t limit = 0;      // RLIMIT_RTPRIO (priority) / RLIMIT_MEMLOCK (bytes)
};

struct StorageCheck {
    std::string dir;              // where recordings go
    std::string existing;         // the nearest existing ancestor (statvfs'd)
    bool exists = false, writable = false;
    std::uint64_t free_bytes = 0;
};

struct ConfigCheck {
    std::string name;             // marionette.toml, render.toml
    std::string file;             // empty: the built-in defaults
    std::string origin;           // --config|user|system|built-in
    std::vector<std::string> searched;
    std::string error;            // a parse or open error
};

struct DoctorReport {
    UserInfo user;
    std::vector<PadNode> pads;
    DisplayCheck display;
    LimitCheck realtime, memlock;
    StorageCheck recordings;
    std::vector<ConfigCheck> configs;
    std::vector<std::string> problems;  // any: exit 1
    std::vector<std::string> warnings;  // run works, but not as a kiosk should
};

// Below this much free space recording is refused as a problem; below the
// second it is a warning.
inline constexpr std::uint64_t kMinFreeBytes = 64ull << 20;
inline constexpr std::uint64_t kLowFreeBytes = 1ull << 30;
// mlockall of the whole process needs about this much.
inline constexpr std::uint64_t kMemlockNeeded = 512ull << 20;

// Fills problems and warnings from the facts in the report.
void classify(DoctorReport& report);
std::string to_json(const DoctorReport& report);
std::string to_text(const DoctorReport& report);

}  // namespace marionette::doctor
