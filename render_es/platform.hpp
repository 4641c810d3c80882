#pragma once
// One small interface over the three ways marionette gets an EGL context and a
// framebuffer to draw into: a headless surfaceless context rendering into an FBO,
// an SDL2 window under a compositor, and KMS/GBM straight on a display with no
// compositor. Each lives in its own file (platform_headless.cpp,
// platform_sdl_window.cpp, platform_kms.cpp); the choice between them and the KMS
// connector/mode choice are pure functions (platform_select.cpp) so they are
// tested without hardware.
#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "runtime/errors/outcome.hpp"

namespace marionette::render {

// A platform could not be opened (no display, no DRM device, no permission, no
// GLES 3 context). The message says which platform and what failed.
class PlatformError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

enum class PlatformKind { headless, window, kms };
enum class PlatformRequest { automatic, headless, window, kms };

const char* platform_name(PlatformKind kind);

// What the selection looks at, gathered by detect_display_environment() (reads
// environment variables and /dev/dri) or written out by a test.
struct DisplayEnvironment {
    bool has_x11_display = false;      // DISPLAY set
    bool has_wayland_display = false;  // WAYLAND_DISPLAY set
    bool has_drm_device = false;       // a /dev/dri/card* node exists
    bool on_virtual_terminal = false;  // stdin is a Linux VT (a bare console)
};
DisplayEnvironment detect_display_environment();

// automatic: a window when a compositor or X server is there, KMS on a bare
// console with a DRM device, else headless. An explicit request is honoured.
PlatformKind select_platform(PlatformRequest request, const DisplayEnvironment& environment);

// --- KMS connector and mode choice (pure) -----------------------------------

struct KmsMode {
    std::int32_t width = 0;
    std::int32_t height = 0;
    std::int32_t refresh_mhz = 0;  // millihertz, as DRM reports clock/htotal/vtotal
    bool preferred = false;        // DRM_MODE_TYPE_PREFERRED
};

struct KmsConnector {
    std::uint32_t id = 0;
    std::string name;              // e.g. "HDMI-A-1", "eDP-1"
    bool connected = false;
    std::vector<KmsMode> modes;
};

enum class KmsModePolicy { preferred, highest_refresh };

struct KmsModeRequest {
    std::string connector;         // empty: the first connected one
    std::int32_t width = 0;        // 0: no forced size
    std::int32_t height = 0;
    std::int32_t refresh_hz = 0;   // 0: any refresh (highest wins) for a forced size
    KmsModePolicy policy = KmsModePolicy::preferred;
};

struct KmsChoice {
    int connector_index = -1;
    int mode_index = -1;
    Outcome chosen = Outcome::success();  // fails naming what is missing
};

// Connector: the named one (it must be connected) or the first connected one.
// Mode: a forced size (and refresh, within 1 Hz) when the request has one, the
// highest refresh among them; else by policy: `preferred` takes the mode the
// display prefers (else the largest, then fastest), `highest_refresh` the fastest
// mode (ties: the largest).
KmsChoice choose_kms_mode(std::span<const KmsConnector> connectors, const KmsModeRequest& request);

// --- the platform interface --------------------------------------------------

struct PlatformOptions {
    PlatformKind kind = PlatformKind::headless;
    std::int32_t width = 1280;     // headless framebuffer / initial window size
    std::int32_t height = 800;
    std::int32_t msaa_samples = 4; // 0 or 1: none
    bool vsync = true;
    bool fullscreen = false;       // window platform
    std::string title = "marionette";
    std::string drm_device;        // KMS: empty picks the first /dev/dri/card* with a connected display
    KmsModeRequest kms_mode;
};

struct PlatformEvents {
    bool close_requested = false;
    bool resized = false;
    bool screenshot_requested = false;  // F12 / P in a window
    bool toggle_skeleton = false;       // key 1
    bool toggle_feet = false;           // key 2
    bool toggle_gait = false;           // key 3
    bool toggle_motion_graph = false;   // key 4
    bool toggle_hud = false;            // H
};

enum class PresentResult { ok, failed, context_lost };

// Something drawn over the scene that takes the window's events first (the
// tuning UI, app/ui/). poll_events() hands it each native event (an SDL_Event
// in a window; KMS and headless have none) before acting on it itself.
class NativeEventHook {
public:
    virtual ~NativeEventHook() = default;
    // True: the hook consumed the event and the platform ignores it.
    virtual bool on_native_event(const void* event) = 0;
};

class Platform {
public:
    virtual ~Platform() = default;
    virtual PlatformKind kind() const = 0;
    // Drawable size in pixels (changes when a window is resized).
    virtual std::int32_t width() const = 0;
    virtual std::int32_t height() const = 0;
    // Binds the framebuffer this frame draws into (an FBO for headless and MSAA)
    // and makes the context current on the calling thread.
    virtual void begin_frame() = 0;
    // Resolves MSAA and shows the frame: a buffer swap (vsync-paced in a window),
    // a page flip on the next vblank (KMS), nothing for headless.
    virtual PresentResult present() = 0;
    // When the last present() reached the screen, CLOCK_MONOTONIC ns, where the
    // platform is told (KMS: the page-flip event's vblank time); 0 when unknown.
    virtual std::int64_t last_present_ns() const { return 0; }
    // Leaves the context current on no thread, so another thread's begin_frame()
    // can take it (a display opened on the main thread, drawn by the render thread).
    virtual void release_current() = 0;
    // Drains window/input events without blocking.
    virtual PlatformEvents poll_events() = 0;
    // After context_lost or a failed present: rebuilds the context and surface.
    // The caller then recreates its GL resources. False when that failed too.
    virtual bool recover() = 0;
    // The last presented (resolved) frame, RGBA8, top row first.
    virtual void read_pixels(std::vector<std::uint8_t>& rgba) = 0;
    // Human-readable "EGL 1.5, OpenGL ES 3.2 Mesa ..., llvmpipe ..."
    virtual std::string description() const = 0;
    // The window's SDL_Window* and SDL_GLContext (nullptr on KMS and headless).
    virtual void* native_window() const { return nullptr; }
    virtual void* native_context() const { return nullptr; }
    // poll_events() offers each event to `hook` first (null: none).
    void set_native_event_hook(NativeEventHook* hook) { hook_ = hook; }

protected:
    NativeEventHook* hook_ = nullptr;
};

// recover()'s shape on every platform: tear the context down, then build it
// again; false when building throws.
template <typename Teardown, typename Build>
bool rebuild(Teardown&& teardown, Build&& build) {
    teardown();
    try {
        build();
    } catch (const std::exception&) {
        return false;
    }
    return true;
}

// Opens the platform options.kind names. Throws PlatformError.
std::unique_ptr<Platform> open_platform(const PlatformOptions& options);
std::unique_ptr<Platform> open_headless_platform(const PlatformOptions& options);
std::unique_ptr<Platform> open_window_platform(const PlatformOptions& options);
std::unique_ptr<Platform> open_kms_platform(const PlatformOptions& options);

}  // namespace marionette::render
