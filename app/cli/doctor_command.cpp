// `marionette doctor [--json]`: is this machine ready to run marionette? Pads
// visible and readable (and which permission, group or rule is missing when
// not), their report rate, the display path `run --display auto` takes, whether
// realtime priority and memory locking are allowed, free space for recordings,
// and the configuration files in effect. Exit 0 when it can run, 1 with the
// problems listed. Nothing here needs root, opens a window or takes DRM master.
#include <fcntl.h>
#include <grp.h>
#include <linux/input.h>
#include <poll.h>
#include <pwd.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "app/cli/cli.hpp"
#include "app/cli/doctor.hpp"
#include "app/live/recording.hpp"
#include "app/config/config.hpp"
#include "app/config/config_search.hpp"
#include "app/config/render_config.hpp"
#include "app/io/json.hpp"
#include "app/live/clock.hpp"
#include "input/hid/hid_report.hpp"
#include "render_es/kms_probe.hpp"
#include "render_es/platform.hpp"

namespace marionette::doctor {

// --- pure rules --------------------------------------------------------------

std::string explain_unreadable(const std::string& description, const NodeAccess& node, const UserInfo& user,
                               bool udev_rule_installed, int open_errno) {
    const std::string what = node.path + " (" + description + ")";
    if (open_errno != EACCES && open_errno != EPERM) return what + ": cannot open: " + std::strerror(open_errno);
    const std::string owned = fmt::format("owned {}:{} mode {:04o}", node.owner, node.group, node.mode & 07777);
    const bool in_group = std::find(user.groups.begin(), user.groups.end(), node.group) != user.groups.end();
    if (node.group == "marionette" && !in_group)
        return fmt::format("{}: {}, and {} is not in group marionette: `usermod -aG marionette {}`, then log in again "
                           "(or run in the active seat's session, which uaccess grants)",
                           what, owned, user.name, user.name);
    if (in_group && (node.mode & 0040) == 0)
        return fmt::format("{}: {}: the group may not read it (the udev rule's MODE=\"0660\" did not apply: "
                           "`udevadm control --reload-rules && udevadm trigger`)",
                           what, owned);
    if (udev_rule_installed)
        return fmt::format("{}: {}, not readable by {}: 70-marionette.rules is installed but did not apply to this "
                           "node: `udevadm control --reload-rules && udevadm trigger`, or replug the pad",
                           what, owned, user.name);
    return fmt::format("{}: {}, not readable by {}: no udev rule for it: install 70-marionette.rules (the marionette "
                       "package does; group marionette, uaccess for the seat's user)",
                       what, owned, user.name);
}

void classify(DoctorReport& r) {
    for (const PadNode& pad : r.pads)
        if (!pad.readable) r.problems.push_back(pad.problem);
    if (r.pads.empty()) r.warnings.push_back("no pad visible: `run --input auto` plays the demo with the simulated controller");
    if (r.display.request == "kms" && r.display.kms_connector.empty())
        r.problems.push_back("display: --display kms would fail: " + r.display.reason);
    else if (r.display.request == "auto" && r.display.choice == "kms" && r.display.kms_connector.empty())
        r.warnings.push_back("display: auto picks kms but " + r.display.reason + "; run would fall back to headless");
    if (!r.realtime.allowed)
        r.warnings.push_back(fmt::format("realtime priority not allowed (RLIMIT_RTPRIO {}, no CAP_SYS_NICE): a [realtime] "
                                         "priority is refused and run keeps normal scheduling (LimitRTPRIO= in the unit grants it)",
                                         r.realtime.limit));
    if (!r.memlock.allowed)
        r.warnings.push_back(fmt::format("memory locking limited (RLIMIT_MEMLOCK {} bytes, no CAP_IPC_LOCK): [realtime] "
                                         "lock_memory is refused (LimitMEMLOCK=infinity in the unit grants it)",
                                         r.memlock.limit));
    const StorageCheck& s = r.recordings;
    if (!s.writable)
        r.problems.push_back("recordings: " + s.existing + " is not writable by " + r.user.name + " (recordings go to " +
                             s.dir + ")");
    else if (s.free_bytes < kMinFreeBytes)
        r.problems.push_back(fmt::format("recordings: only {} MiB free under {}", s.free_bytes >> 20, s.existing));
    else if (s.free_bytes < kLowFreeBytes)
        r.warnings.push_back(fmt::format("recordings: {} MiB free under {}", s.free_bytes >> 20, s.existing));
    for (const ConfigCheck& c : r.configs)
        if (!c.error.empty()) r.problems.push_back("config: " + c.error);
}

namespace {
std::string json_strings(const std::vector<std::string>& v) {
    std::string out = "[";
    for (std::size_t i = 0; i < v.size(); ++i) out += (i ? "," : "") + json::quote(v[i]);
    return out + "]";
}
const char* json_bool(bool b) { return b ? "true" : "false"; }

std::string pad_json(const PadNode& p) {
    return fmt::format("{{\"path\":{},\"backend\":{},\"name\":{},\"vendor_id\":\"{:04x}\",\"product_id\":\"{:04x}\","
                       "\"readable\":{},\"problem\":{},\"report_rate_hz\":{},\"reports\":{}}}",
                       json::quote(p.path), json::quote(p.backend), json::quote(p.name), p.vendor_id, p.product_id,
                       json_bool(p.readable), p.problem.empty() ? "null" : json::quote(p.problem),
                       p.report_rate_hz < 0 ? "null" : json::number(p.report_rate_hz), p.reports);
}

std::string limit_json(const LimitCheck& l) {
    return fmt::format("{{\"allowed\":{},\"capability\":{},\"unlimited\":{},\"limit\":{}}}", json_bool(l.allowed),
                       json_bool(l.capability), json_bool(l.unlimited), l.unlimited ? "null" : json::number(l.limit));
}
}  // namespace

std::string to_json(const DoctorReport& r) {
    std::string pads = "[";
    for (std::size_t i = 0; i < r.pads.size(); ++i) pads += (i ? "," : "") + pad_json(r.pads[i]);
    pads += "]";
    std::string configs = "[";
    for (std::size_t i = 0; i < r.configs.size(); ++i) {
        const ConfigCheck& c = r.configs[i];
        configs += fmt::format("{}{{\"name\":{},\"file\":{},\"origin\":{},\"searched\":{},\"error\":{}}}", i ? "," : "",
                               json::quote(c.name), c.file.empty() ? "null" : json::quote(c.file), json::quote(c.origin),
                               json_strings(c.searched), c.error.empty() ? "null" : json::quote(c.error));
    }
    configs += "]";
    const DisplayCheck& d = r.display;
    const std::string display = fmt::format(
        "{{\"request\":{},\"choice\":{},\"reason\":{},\"kms_device\":{},\"kms_connector\":{},\"kms_mode\":{}}}",
        json::quote(d.request), json::quote(d.choice), json::quote(d.reason),
        d.kms_device.empty() ? "null" : json::quote(d.kms_device),
        d.kms_connector.empty() ? "null" : json::quote(d.kms_connector), d.kms_mode.empty() ? "null" : json::quote(d.kms_mode));
    const StorageCheck& s = r.recordings;
    const std::string storage = fmt::format("{{\"dir\":{},\"exists\":{},\"existing\":{},\"writable\":{},\"free_bytes\":{}}}",
                                            json::quote(s.dir), json_bool(s.exists), json::quote(s.existing),
                                            json_bool(s.writable), s.free_bytes);
    return fmt::format("{{\"ok\":{},\"user\":{},\"groups\":{},\"pads\":{},\"display\":{},\"realtime\":{},\"memlock\":{},"
                       "\"recordings\":{},\"config\":{},\"problems\":{},\"warnings\":{}}}\n",
                       json_bool(r.problems.empty()), json::quote(r.user.name), json_strings(r.user.groups), pads, display,
                       limit_json(r.realtime), limit_json(r.memlock), storage, configs, json_strings(r.problems),
                       json_strings(r.warnings));
}

std::string to_text(const DoctorReport& r) {
    std::string out = fmt::format("user: {} (groups: {})\n", r.user.name, fmt::join(r.user.groups, ", "));
    if (r.pads.empty()) out += "pads: none visible (/dev/input/event* gamepads, /dev/hidraw* supported pads)\n";
    for (const PadNode& p : r.pads) {
        out += fmt::format("pad: {} {} {:04x}:{:04x} ({}): ", p.backend, p.path, p.vendor_id, p.product_id, p.name);
        if (!p.readable) out += "NOT readable\n";
        else if (p.report_rate_hz < 0) out += "readable\n";
        else out += fmt::format("readable, {:.0f} reports/s measured ({} reports)\n", p.report_rate_hz, p.reports);
    }
    out += fmt::format("display: run --display {} would take {}: {}", r.display.request, r.display.choice, r.display.reason);
    if (!r.display.kms_connector.empty())
        out += fmt::format(" ({} {} {})", r.display.kms_device, r.display.kms_connector, r.display.kms_mode);
    out += "\n";
    out += fmt::format("realtime priority: {} (RLIMIT_RTPRIO {}{})\n", r.realtime.allowed ? "allowed" : "not allowed",
                       r.realtime.unlimited ? std::string("unlimited") : std::to_string(r.realtime.limit),
                       r.realtime.capability ? ", CAP_SYS_NICE" : "");
    out += fmt::format("memory locking: {} (RLIMIT_MEMLOCK {}{})\n", r.memlock.allowed ? "allowed" : "limited",
                       r.memlock.unlimited ? std::string("unlimited") : std::to_string(r.memlock.limit) + " bytes",
                       r.memlock.capability ? ", CAP_IPC_LOCK" : "");
    out += fmt::format("recordings: {}{}, {} MiB free, {}\n", r.recordings.dir, r.recordings.exists ? "" : " (not created yet)",
                       r.recordings.free_bytes >> 20, r.recordings.writable ? "writable" : "NOT writable");
    for (const ConfigCheck& c : r.configs) {
        ConfigLookup l;
        l.searched = c.searched;
        out += fmt::format("{}: {}\n", c.name, c.file.empty() ? describe_config_lookup(l) : c.file + " (" + c.origin + ")");
    }
    for (const std::string& w : r.warnings) out += "warning: " + w + "\n";
    if (r.problems.empty()) return out + "ok: marionette can run\n";
    out += fmt::format("{} problem{}:\n", r.problems.size(), r.problems.size() == 1 ? "" : "s");
    for (const std::string& p : r.problems) out += "  " + p + "\n";
    return out;
}

// --- probes ------------------------------------------------------------------

namespace {
std::string read_first_line(const std::string& path) {
    std::ifstream in(path);
    std::string line;
    std::getline(in, line);
    return line;
}

std::string file_text(const std::string& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

std::string group_name(gid_t gid) {
    const group* g = getgrgid(gid);
    return g != nullptr ? g->gr_name : std::to_string(gid);
}

UserInfo current_user() {
    UserInfo u;
    const passwd* pw = getpwuid(geteuid());
    u.name = pw != nullptr ? pw->pw_name : std::to_string(geteuid());
    u.groups.push_back(group_name(getegid()));
    const int n = getgroups(0, nullptr);
    std::vector<gid_t> gids(static_cast<std::size_t>(std::max(n, 0)));
    if (n > 0 && getgroups(n, gids.data()) == n)
        for (gid_t g : gids)
            if (std::find(u.groups.begin(), u.groups.end(), group_name(g)) == u.groups.end()) u.groups.push_back(group_name(g));
    return u;
}

NodeAccess node_access(const std::string& path) {
    NodeAccess a;
    a.path = path;
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) return a;
    a.mode = st.st_mode & 07777;
    const passwd* pw = getpwuid(st.st_uid);
    a.owner = pw != nullptr ? pw->pw_name : std::to_string(st.st_uid);
    a.group = group_name(st.st_gid);
    return a;
}

bool udev_rule_installed() {
    for (const char* dir : {"/etc/udev/rules.d", "/run/udev/rules.d", "/usr/lib/udev/rules.d", "/lib/udev/rules.d",
                            "/usr/local/lib/udev/rules.d"}) {
        std::error_code ec;
        if (std::filesystem::exists(std::string(dir) + "/70-marionette.rules", ec)) return true;
    }
    return false;
}

// Reads reports for `window_s`: hidraw counts reads, evdev counts SYN_REPORTs.
void measure_rate(int fd, PadNode& pad, double window_s) {
    if (window_s <= 0) return;
    const std::int64_t start = monotonic_ns();
    const std::int64_t end = start + static_cast<std::int64_t>(window_s * 1e9);
    unsigned char buffer[sizeof(input_event) * 64];
    for (std::int64_t now = start; now < end; now = monotonic_ns()) {
        pollfd p{fd, POLLIN, 0};
        const int timeout_ms = static_cast<int>((end - now) / 1'000'000) + 1;
        if (::poll(&p, 1, timeout_ms) <= 0) continue;
        const ssize_t n = ::read(fd, buffer, sizeof buffer);
        if (n <= 0) break;
        if (pad.backend == "hidraw") {
            ++pad.reports;
            continue;
        }
        for (std::size_t i = 0; i + sizeof(input_event) <= static_cast<std::size_t>(n); i += sizeof(input_event)) {
            input_event e{};
            std::memcpy(&e, buffer + i, sizeof e);
            if (e.type == EV_SYN && e.code == SYN_REPORT) ++pad.reports;
        }
    }
    pad.report_rate_hz = static_cast<double>(pad.reports) / window_s;
}

void check_node(PadNode pad, const UserInfo& user, double window_s, std::vector<PadNode>& out) {
    const int fd = ::open(pad.path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        const int err = errno;
        const std::string desc = fmt::format("{} {:04x}:{:04x}", pad.name, pad.vendor_id, pad.product_id);
        pad.problem = explain_unreadable(desc, node_access(pad.path), user, udev_rule_installed(), err);
    } else {
        pad.readable = true;
        measure_rate(fd, pad, window_s);
        ::close(fd);
    }
    out.push_back(std::move(pad));
}

std::uint16_t hex16(const std::string& text) { return static_cast<std::uint16_t>(std::strtoul(text.c_str(), nullptr, 16)); }

// Supported HID pads: /sys/class/hidraw/hidrawN/device/uevent has
// HID_ID=BUS:VENDOR:PRODUCT (32-bit hex each) and HID_NAME.
void find_hidraw_pads(const UserInfo& user, double window_s, std::vector<PadNode>& out) {
    std::error_code ec;
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator("/sys/class/hidraw", ec)) names.push_back(e.path().filename());
    std::sort(names.begin(), names.end());
    for (const std::string& name : names) {
        const std::string sys = "/sys/class/hidraw/" + name + "/device";
        PadNode pad;
        pad.path = "/dev/" + name;
        pad.backend = "hidraw";
        std::istringstream uevent(file_text(sys + "/uevent"));
        for (std::string line; std::getline(uevent, line);) {
            if (line.rfind("HID_ID=", 0) == 0 && line.size() >= 7 + 22) {
                pad.vendor_id = hex16(line.substr(7 + 5 + 4, 4));
                pad.product_id = hex16(line.substr(7 + 14 + 4, 4));
            } else if (line.rfind("HID_NAME=", 0) == 0) {
                pad.name = line.substr(9);
            }
        }
        const std::string iface = read_first_line(sys + "/../bInterfaceNumber");
        const int interface_number = iface.empty() ? -1 : static_cast<int>(std::strtol(iface.c_str(), nullptr, 16));
        const auto kind = input::find_hid_device_kind(pad.vendor_id, pad.product_id, interface_number);
        if (!kind) continue;  // keyboards, mice, other HID: not ours
        pad.name = std::string(kind->name);
        check_node(std::move(pad), user, window_s, out);
    }
}

// Gamepads among /sys/class/input/eventN: udev's ID_INPUT_JOYSTICK, or (no udev
// database, e.g. a container) the key capability bitmap holding BTN_GAMEPAD.
bool is_gamepad(const std::string& event_name) {
    const std::string dev = read_first_line("/sys/class/input/" + event_name + "/dev");  // "13:67"
    if (!dev.empty() && file_text("/run/udev/data/c" + dev).find("E:ID_INPUT_JOYSTICK=1") != std::string::npos) return true;
    std::istringstream words(read_first_line("/sys/class/input/" + event_name + "/device/capabilities/key"));
    std::vector<std::string> longs;
    for (std::string w; words >> w;) longs.push_back(w);
    constexpr unsigned kBits = sizeof(unsigned long) * 8;
    const std::size_t index = BTN_GAMEPAD / kBits;  // counted from the last word
    if (longs.size() <= index) return false;
    const unsigned long word = std::strtoul(longs[longs.size() - 1 - index].c_str(), nullptr, 16);
    return ((word >> (BTN_GAMEPAD % kBits)) & 1ul) != 0;
}

void find_evdev_pads(const UserInfo& user, double window_s, std::vector<PadNode>& out) {
    std::error_code ec;
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator("/sys/class/input", ec))
        if (e.path().filename().string().rfind("event", 0) == 0) names.push_back(e.path().filename());
    std::sort(names.begin(), names.end());
    for (const std::string& name : names) {
        if (!is_gamepad(name)) continue;
        const std::string sys = "/sys/class/input/" + name + "/device";
        PadNode pad;
        pad.path = "/dev/input/" + name;
        pad.backend = "evdev";
        pad.name = read_first_line(sys + "/name");
        pad.vendor_id = hex16(read_first_line(sys + "/id/vendor"));
        pad.product_id = hex16(read_first_line(sys + "/id/product"));
        check_node(std::move(pad), user, window_s, out);
    }
}

DisplayCheck check_display(const std::string& request, const RenderConfig& rc) {
    DisplayCheck d;
    d.request = request;
    const render::DisplayEnvironment env = render::detect_display_environment();
    const render::PlatformRequest req = request == "window"     ? render::PlatformRequest::window
                                        : request == "kms"      ? render::PlatformRequest::kms
                                        : request == "headless" ? render::PlatformRequest::headless
                                                                : render::PlatformRequest::automatic;
    const render::PlatformKind kind = render::select_platform(req, env);
    d.choice = render::platform_name(kind);
    if (req != render::PlatformRequest::automatic) d.reason = "asked for by name";
    else if (env.has_wayland_display || env.has_x11_display)
        d.reason = env.has_wayland_display ? "WAYLAND_DISPLAY is set" : "DISPLAY is set";
    else if (env.has_drm_device && env.on_virtual_terminal) d.reason = "a DRM device and stdin on a Linux VT";
    else
        d.reason = std::string("no DISPLAY or WAYLAND_DISPLAY, and ") +
                   (env.has_drm_device ? "stdin is not a Linux VT" : "no DRM device (/dev/dri/card*)");
    if (kind != render::PlatformKind::kms) return d;
    std::vector<std::string> errors;
    for (const render::KmsCardProbe& card : render::probe_kms_cards(rc.kms)) {
        if (!rc.drm_device.empty() && card.path != rc.drm_device) continue;
        if (!card.opened || !card.error.empty() || !card.choice.chosen.ok()) {
            const std::string why = !card.error.empty() ? card.error : card.choice.chosen.problem();
            const NodeAccess a = node_access(card.path);
            errors.push_back(fmt::format("{}: {} (owned {}:{} mode {:04o})", card.path, why, a.owner, a.group, a.mode));
            continue;
        }
        const render::KmsConnector& c = card.connectors[static_cast<std::size_t>(card.choice.connector_index)];
        const render::KmsMode& m = c.modes[static_cast<std::size_t>(card.choice.mode_index)];
        d.kms_device = card.path;
        d.kms_connector = c.name;
        d.kms_mode = fmt::format("{}x{}@{:.2f}Hz", m.width, m.height, m.refresh_mhz / 1000.0);
        return d;
    }
    d.reason += "; no usable KMS output: " + (errors.empty() ? std::string("no /dev/dri/card*") : fmt::format("{}", fmt::join(errors, "; ")));
    return d;
}

bool has_capability(int bit) {
    std::istringstream status(file_text("/proc/self/status"));
    for (std::string line; std::getline(status, line);)
        if (line.rfind("CapEff:", 0) == 0) return ((std::strtoull(line.c_str() + 7, nullptr, 16) >> bit) & 1ull) != 0;
    return false;
}

LimitCheck check_limit(int resource, int capability, std::uint64_t needed) {
    LimitCheck l;
    rlimit r{};
    getrlimit(resource, &r);
    l.unlimited = r.rlim_cur == RLIM_INFINITY;
    l.limit = l.unlimited ? 0 : static_cast<std::uint64_t>(r.rlim_cur);
    l.capability = has_capability(capability);
    l.allowed = l.capability || l.unlimited || l.limit >= needed;
    return l;
}

// Where `run --record auto` writes (app/live/recording.hpp): the service's
// StateDirectory (systemd sets STATE_DIRECTORY), else $XDG_STATE_HOME/marionette,
// else ~/.local/state/marionette.
StorageCheck check_storage() {
    StorageCheck s;
    s.dir = default_recordings_dir();
    std::error_code ec;
    std::filesystem::path p = s.dir;
    s.exists = std::filesystem::is_directory(p, ec);
    while (!p.empty() && p != p.root_path() && !std::filesystem::exists(p, ec)) p = p.parent_path();
    s.existing = p.string();
    s.writable = ::access(s.existing.c_str(), W_OK) == 0;
    struct statvfs v {};
    if (::statvfs(s.existing.c_str(), &v) == 0) s.free_bytes = static_cast<std::uint64_t>(v.f_bavail) * v.f_frsize;
    return s;
}

template <typename Load>
ConfigCheck check_config(const std::string& explicit_file, const std::string& name, const ConfigSearchDirs& dirs, Load load) {
    const ConfigLookup l = find_config_file(explicit_file, name, dirs);
    ConfigCheck c;
    c.name = name;
    c.file = l.file;
    c.origin = config_origin_name(l.origin);
    c.searched = l.searched;
    try {
        load(l.file);
    } catch (const std::exception& e) {
        c.error = e.what();
    }
    return c;
}

struct DoctorOptions {
    bool json = false;
    std::string config_file;
    std::string display = "auto";
    double rate_window_s = 0.5;
};

int doctor_command(const DoctorOptions& o) {
    DoctorReport r;
    r.user = current_user();
    find_hidraw_pads(r.user, o.rate_window_s, r.pads);
    find_evdev_pads(r.user, o.rate_window_s, r.pads);
    const ConfigSearchDirs dirs = config_search_dirs_from_environment();
    r.configs.push_back(check_config(o.config_file, "marionette.toml", dirs, [](const std::string& f) { load_config(f); }));
    RenderConfig rc;
    r.configs.push_back(check_config("", "render.toml", dirs, [&rc](const std::string& f) { rc = load_render_config(f); }));
    r.display = check_display(o.display, rc);
    r.realtime = check_limit(RLIMIT_RTPRIO, 23 /* CAP_SYS_NICE */, 1);
    r.memlock = check_limit(RLIMIT_MEMLOCK, 14 /* CAP_IPC_LOCK */, kMemlockNeeded);
    r.recordings = check_storage();
    classify(r);
    fmt::print("{}", o.json ? to_json(r) : to_text(r));
    return r.problems.empty() ? 0 : 1;
}
}  // namespace

}  // namespace marionette::doctor

namespace marionette {

void register_doctor_command(CLI::App& app, int& exit_code) {
    auto o = std::make_shared<doctor::DoctorOptions>();
    CLI::App* cmd = app.add_subcommand("doctor", "Check pads, display, limits, disk and config before going live (exit 1: problems)");
    cmd->add_flag("--json", o->json, "print the report as one JSON object");
    cmd->add_option("--config", o->config_file, "the TOML file run would be given (default: the search run does)");
    cmd->add_option("--display", o->display, "the display run would be asked for: auto|kms|window|headless")
        ->check(CLI::IsMember({"auto", "headless", "kms", "window"}));
    cmd->add_option("--rate-window", o->rate_window_s, "seconds to count each readable pad's reports (0: do not measure)")
        ->check(CLI::Range(0.0, 10.0));
    on_parsed(cmd, exit_code, [o] { return doctor::doctor_command(*o); });
}

}  // namespace marionette
