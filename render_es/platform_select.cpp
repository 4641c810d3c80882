// Platform selection and KMS connector/mode choice: pure functions over described
// environments and mode lists, so they are tested without displays or GPUs.
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <sys/stat.h>
#include <sys/sysmacros.h>

#include "render_es/platform.hpp"

namespace marionette::render {

const char* platform_name(PlatformKind kind) {
    switch (kind) {
        case PlatformKind::headless: return "headless";
        case PlatformKind::window: return "window";
        case PlatformKind::kms: return "kms";
    }
    return "?";
}

namespace {
bool env_set(const char* name) {
    const char* v = std::getenv(name);
    return v != nullptr && *v != '\0';
}

bool stdin_is_linux_vt() {
    struct stat st {};
    if (fstat(STDIN_FILENO, &st) != 0 || !S_ISCHR(st.st_mode)) return false;
    // Linux VTs are character devices with major 4, minors 0..63 (tty0..tty63).
    return major(st.st_rdev) == 4 && minor(st.st_rdev) < 64;
}
}  // namespace

DisplayEnvironment detect_display_environment() {
    DisplayEnvironment e;
    e.has_x11_display = env_set("DISPLAY");
    e.has_wayland_display = env_set("WAYLAND_DISPLAY");
    std::error_code ec;
    if (std::filesystem::is_directory("/dev/dri", ec)) {
        for (const auto& entry : std::filesystem::directory_iterator("/dev/dri", ec))
            if (entry.path().filename().string().rfind("card", 0) == 0) e.has_drm_device = true;
    }
    e.on_virtual_terminal = stdin_is_linux_vt();
    return e;
}

PlatformKind select_platform(PlatformRequest request, const DisplayEnvironment& env) {
    switch (request) {
        case PlatformRequest::headless: return PlatformKind::headless;
        case PlatformRequest::window: return PlatformKind::window;
        case PlatformRequest::kms: return PlatformKind::kms;
        case PlatformRequest::automatic: break;
    }
    if (env.has_wayland_display || env.has_x11_display) return PlatformKind::window;
    if (env.has_drm_device && env.on_virtual_terminal) return PlatformKind::kms;
    return PlatformKind::headless;
}

namespace {
long long area(const KmsMode& m) { return static_cast<long long>(m.width) * m.height; }

// True when a is a better fallback than b: larger, then faster.
bool larger_then_faster(const KmsMode& a, const KmsMode& b) {
    if (area(a) != area(b)) return area(a) > area(b);
    return a.refresh_mhz > b.refresh_mhz;
}

// True when a is faster than b; ties go to the larger mode.
bool faster_then_larger(const KmsMode& a, const KmsMode& b) {
    if (a.refresh_mhz != b.refresh_mhz) return a.refresh_mhz > b.refresh_mhz;
    return area(a) > area(b);
}
}  // namespace

KmsChoice choose_kms_mode(std::span<const KmsConnector> connectors, const KmsModeRequest& request) {
    KmsChoice choice;
    for (size_t i = 0; i < connectors.size(); ++i) {
        const KmsConnector& c = connectors[i];
        if (!request.connector.empty()) {
            if (c.name != request.connector) continue;
            if (!c.connected) {
                choice.chosen = Outcome::failure("connector " + c.name + " has no display connected");
                return choice;
            }
        }
        if (!c.connected || c.modes.empty()) continue;
        choice.connector_index = static_cast<int>(i);
        break;
    }
    if (choice.connector_index < 0) {
        choice.chosen = Outcome::failure(request.connector.empty() ? std::string("no connector has a display connected")
                                                                   : "no connector named " + request.connector);
        return choice;
    }
    const std::vector<KmsMode>& modes = connectors[static_cast<size_t>(choice.connector_index)].modes;
    int best = -1;
    auto consider = [&](int i, bool (*better)(const KmsMode&, const KmsMode&)) {
        if (best < 0 || better(modes[static_cast<size_t>(i)], modes[static_cast<size_t>(best)])) best = i;
    };
    if (request.width > 0 && request.height > 0) {
        for (size_t i = 0; i < modes.size(); ++i) {
            const KmsMode& m = modes[i];
            if (m.width != request.width || m.height != request.height) continue;
            if (request.refresh_hz > 0 && std::abs(m.refresh_mhz - request.refresh_hz * 1000) > 1000) continue;
            consider(static_cast<int>(i), faster_then_larger);
        }
        if (best < 0) {
            choice.chosen = Outcome::failure(
                "connector " + connectors[static_cast<size_t>(choice.connector_index)].name + " offers no mode " +
                std::to_string(request.width) + "x" + std::to_string(request.height) +
                (request.refresh_hz > 0 ? "@" + std::to_string(request.refresh_hz) + "Hz" : std::string()));
            return choice;
        }
    } else if (request.policy == KmsModePolicy::highest_refresh) {
        for (size_t i = 0; i < modes.size(); ++i) consider(static_cast<int>(i), faster_then_larger);
    } else {
        for (size_t i = 0; i < modes.size() && best < 0; ++i)
            if (modes[i].preferred) best = static_cast<int>(i);
        if (best < 0)
            for (size_t i = 0; i < modes.size(); ++i) consider(static_cast<int>(i), larger_then_faster);
    }
    choice.mode_index = best;
    return choice;
}

std::unique_ptr<Platform> open_platform(const PlatformOptions& options) {
    switch (options.kind) {
        case PlatformKind::headless: return open_headless_platform(options);
        case PlatformKind::window: return open_window_platform(options);
        case PlatformKind::kms: return open_kms_platform(options);
    }
    throw PlatformError("unknown platform");
}

}  // namespace marionette::render
