// KMS/GBM platform for kiosks with no compositor (after Mesa's kmscube): open
// the DRM device through libseat (logind or seatd, so no root is needed), pick
// the connector and mode (choose_kms_mode), render through EGL on a GBM surface,
// and show each frame with a page flip paced by the vblank event. Atomic
// modesetting is used when the driver offers it, legacy SetCrtc/PageFlip
// otherwise. The CRTC's previous configuration is restored on exit.
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLES3/gl3.h>
#include <fcntl.h>
#include <gbm.h>
extern "C" {  // libseat.h has no C++ guards
#include <libseat.h>
}
#include <poll.h>
#include <unistd.h>
#include <xf86drm.h>
#include <xf86drmMode.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "render_es/egl_util.hpp"
#include "render_es/gl_util.hpp"
#include "render_es/platform.hpp"

namespace marionette::render {

namespace {
constexpr GLenum kGlContextLost = 0x0507;

[[noreturn]] void fail(const std::string& what) { throw PlatformError("kms platform: " + what); }

// --- seat access ------------------------------------------------------------

struct Seat {
    libseat* seat = nullptr;
    bool active = false;
    int device_id = -1;
    int fd = -1;

    static void enable(libseat*, void* self) { static_cast<Seat*>(self)->active = true; }
    static void disable(libseat* s, void* self) {
        static_cast<Seat*>(self)->active = false;
        libseat_disable_seat(s);
    }

    // Opens `path` through the seat; without a seat (no logind/seatd) falls back to
    // a plain open, which works as root or for members of the video group.
    void open_device(const std::string& path) {
        static const libseat_seat_listener listener{&Seat::enable, &Seat::disable};
        libseat_set_log_level(LIBSEAT_LOG_LEVEL_SILENT);
        seat = libseat_open_seat(&listener, this);
        if (seat != nullptr) {
            for (int i = 0; i < 50 && !active; ++i) libseat_dispatch(seat, 100);
            if (active) device_id = libseat_open_device(seat, path.c_str(), &fd);
            if (device_id >= 0) return;
        }
        fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
        if (fd < 0)
            fail("cannot open " + path + " (" + std::strerror(errno) +
                 "): run from a logind/seatd session on a virtual terminal, or as a member of the video group");
    }

    void close_device() {
        if (seat != nullptr && device_id >= 0) libseat_close_device(seat, device_id);
        else if (fd >= 0) ::close(fd);
        if (seat != nullptr) libseat_close_seat(seat);
        *this = Seat{};
    }
};

// --- DRM objects --------------------------------------------------------------

std::uint32_t property_id(int fd, std::uint32_t object, std::uint32_t type, const char* name) {
    drmModeObjectProperties* props = drmModeObjectGetProperties(fd, object, type);
    std::uint32_t id = 0;
    for (std::uint32_t i = 0; props != nullptr && i < props->count_props && id == 0; ++i) {
        drmModePropertyRes* p = drmModeGetProperty(fd, props->props[i]);
        if (p != nullptr && std::strcmp(p->name, name) == 0) id = p->prop_id;
        drmModeFreeProperty(p);
    }
    drmModeFreeObjectProperties(props);
    return id;
}

struct Scanout {
    std::vector<KmsConnector> connectors;
    std::vector<drmModeModeInfo> raw_modes;  // of the chosen connector, same order as its KmsModes
    std::uint32_t connector_id = 0;
    std::uint32_t crtc_id = 0;
    int crtc_index = -1;
    std::uint32_t plane_id = 0;              // primary plane (atomic only)
    drmModeModeInfo mode{};
};

KmsMode describe(const drmModeModeInfo& m) {
    KmsMode mode;
    mode.width = m.hdisplay;
    mode.height = m.vdisplay;
    const long long pixels = static_cast<long long>(m.htotal) * m.vtotal;
    mode.refresh_mhz = pixels > 0 ? static_cast<std::int32_t>(static_cast<long long>(m.clock) * 1000000LL / pixels) : m.vrefresh * 1000;
    mode.preferred = (m.type & DRM_MODE_TYPE_PREFERRED) != 0;
    return mode;
}

Scanout choose_scanout(int fd, const KmsModeRequest& request, const std::string& device) {
    drmModeRes* res = drmModeGetResources(fd);
    if (res == nullptr) fail(device + " is not a KMS device (drmModeGetResources failed)");
    Scanout s;
    std::vector<std::vector<drmModeModeInfo>> raw;
    for (int i = 0; i < res->count_connectors; ++i) {
        drmModeConnector* c = drmModeGetConnector(fd, res->connectors[i]);
        if (c == nullptr) continue;
        KmsConnector k;
        k.id = c->connector_id;
        k.name = std::string(drmModeGetConnectorTypeName(c->connector_type) ? drmModeGetConnectorTypeName(c->connector_type) : "Unknown") +
                 "-" + std::to_string(c->connector_type_id);
        k.connected = c->connection == DRM_MODE_CONNECTED;
        raw.emplace_back(c->modes, c->modes + c->count_modes);
        for (int m = 0; m < c->count_modes; ++m) k.modes.push_back(describe(c->modes[m]));
        s.connectors.push_back(std::move(k));
        drmModeFreeConnector(c);
    }
    const KmsChoice choice = choose_kms_mode(s.connectors, request);
    if (!choice.chosen.ok()) {
        drmModeFreeResources(res);
        fail(device + ": " + choice.chosen.problem());
    }
    const KmsConnector& chosen = s.connectors[static_cast<size_t>(choice.connector_index)];
    s.connector_id = chosen.id;
    s.raw_modes = raw[static_cast<size_t>(choice.connector_index)];
    s.mode = s.raw_modes[static_cast<size_t>(choice.mode_index)];

    // A CRTC the connector's encoders can drive: the current one if any.
    drmModeConnector* c = drmModeGetConnector(fd, s.connector_id);
    for (int e = 0; c != nullptr && e < c->count_encoders && s.crtc_id == 0; ++e) {
        drmModeEncoder* enc = drmModeGetEncoder(fd, c->encoders[e]);
        if (enc == nullptr) continue;
        if (enc->crtc_id != 0 && c->encoder_id == enc->encoder_id) s.crtc_id = enc->crtc_id;
        for (int i = 0; i < res->count_crtcs && s.crtc_id == 0; ++i)
            if (enc->possible_crtcs & (1u << i)) s.crtc_id = res->crtcs[i];
        drmModeFreeEncoder(enc);
    }
    drmModeFreeConnector(c);
    for (int i = 0; i < res->count_crtcs; ++i)
        if (res->crtcs[i] == s.crtc_id) s.crtc_index = i;
    drmModeFreeResources(res);
    if (s.crtc_id == 0) fail(device + ": no CRTC can drive connector " + chosen.name);
    return s;
}

std::uint32_t primary_plane(int fd, int crtc_index) {
    drmModePlaneRes* planes = drmModeGetPlaneResources(fd);
    std::uint32_t found = 0;
    for (std::uint32_t i = 0; planes != nullptr && i < planes->count_planes && found == 0; ++i) {
        drmModePlane* p = drmModeGetPlane(fd, planes->planes[i]);
        if (p != nullptr && (p->possible_crtcs & (1u << crtc_index))) {
            drmModeObjectProperties* props = drmModeObjectGetProperties(fd, p->plane_id, DRM_MODE_OBJECT_PLANE);
            for (std::uint32_t k = 0; props != nullptr && k < props->count_props; ++k) {
                drmModePropertyRes* prop = drmModeGetProperty(fd, props->props[k]);
                if (prop != nullptr && std::strcmp(prop->name, "type") == 0 && props->prop_values[k] == DRM_PLANE_TYPE_PRIMARY)
                    found = p->plane_id;
                drmModeFreeProperty(prop);
            }
            drmModeFreeObjectProperties(props);
        }
        drmModeFreePlane(p);
    }
    drmModeFreePlaneResources(planes);
    return found;
}

std::string first_card_with_display(const KmsModeRequest& request) {
    std::error_code ec;
    std::vector<std::string> cards;
    for (const auto& entry : std::filesystem::directory_iterator("/dev/dri", ec))
        if (entry.path().filename().string().rfind("card", 0) == 0) cards.push_back(entry.path().string());
    std::sort(cards.begin(), cards.end());
    for (const std::string& card : cards) {
        const int fd = ::open(card.c_str(), O_RDWR | O_CLOEXEC);
        if (fd < 0) return card;  // no permission to probe: let the seat open it
        bool usable = false;
        try {
            choose_scanout(fd, request, card);
            usable = true;
        } catch (const PlatformError&) {
        }
        ::close(fd);
        if (usable) return card;
    }
    if (cards.empty()) fail("no DRM device (/dev/dri/card*); use --display window or headless");
    return cards.front();
}

// --- the platform ---------------------------------------------------------------

class KmsPlatform final : public Platform {
public:
    explicit KmsPlatform(const PlatformOptions& options) : options_(options) {
        device_ = options.drm_device.empty() ? first_card_with_display(options.kms_mode) : options.drm_device;
        seat_.open_device(device_);
        try {
            open_display();
        } catch (...) {
            close_display();
            seat_.close_device();
            throw;
        }
    }

    ~KmsPlatform() override {
        close_display();
        seat_.close_device();
    }

    PlatformKind kind() const override { return PlatformKind::kms; }
    std::int32_t width() const override { return scanout_.mode.hdisplay; }
    std::int32_t height() const override { return scanout_.mode.vdisplay; }

    void begin_frame() override {
        if (eglGetCurrentContext() != context_) eglMakeCurrent(egl_display_, surface_, surface_, context_);
        glBindFramebuffer(GL_FRAMEBUFFER, draw_.framebuffer);
        glViewport(0, 0, width(), height());
    }

    PresentResult present() override {
        draw_.present_to(0, width(), height(), resolved_);
        if (!eglSwapBuffers(egl_display_, surface_))
            return eglGetError() == EGL_CONTEXT_LOST ? PresentResult::context_lost : PresentResult::failed;
        if (glGetError() == kGlContextLost) return PresentResult::context_lost;
        gbm_bo* next = gbm_surface_lock_front_buffer(gbm_surface_);
        if (next == nullptr) return PresentResult::failed;
        const std::uint32_t fb = framebuffer_for(next);
        if (fb == 0) {
            gbm_surface_release_buffer(gbm_surface_, next);
            return PresentResult::failed;
        }
        if (!mode_set_) {
            if (!set_mode(fb)) {
                gbm_surface_release_buffer(gbm_surface_, next);
                return PresentResult::failed;
            }
            mode_set_ = true;
        } else if (!flip(fb)) {
            gbm_surface_release_buffer(gbm_surface_, next);
            return PresentResult::failed;
        } else {
            wait_for_flip();  // paced by vblank: the render thread's only wait
        }
        if (front_ != nullptr) gbm_surface_release_buffer(gbm_surface_, front_);
        front_ = next;
        return PresentResult::ok;
    }

    std::int64_t last_present_ns() const override { return flip_time_ns_; }

    void release_current() override { eglMakeCurrent(egl_display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT); }

    PlatformEvents poll_events() override {
        PlatformEvents e;
        if (seat_.seat != nullptr) libseat_dispatch(seat_.seat, 0);  // VT switches
        return e;
    }

    bool recover() override { return rebuild([this] { close_display(); }, [this] { open_display(); }); }

    void read_pixels(std::vector<std::uint8_t>& rgba) override {
        draw_.resolve_to_single(resolved_, width(), height());
        read_rgba_top_down(resolved_.framebuffer, width(), height(), rgba);
    }

    std::string description() const override {
        const KmsMode m = describe(scanout_.mode);
        return "kms " + device_ + " " + std::to_string(m.width) + "x" + std::to_string(m.height) + "@" +
               std::to_string(m.refresh_mhz / 1000) + "." + std::to_string(m.refresh_mhz % 1000 / 100) + "Hz, " +
               (atomic_ ? "atomic" : "legacy") + " modesetting, " + gl_;
    }

private:
    void open_display() {
        const int fd = seat_.fd;
        scanout_ = choose_scanout(fd, options_.kms_mode, device_);
        saved_crtc_ = drmModeGetCrtc(fd, scanout_.crtc_id);
        atomic_ = drmSetClientCap(fd, DRM_CLIENT_CAP_UNIVERSAL_PLANES, 1) == 0 &&
                  drmSetClientCap(fd, DRM_CLIENT_CAP_ATOMIC, 1) == 0;
        if (atomic_) {
            scanout_.plane_id = primary_plane(fd, scanout_.crtc_index);
            atomic_ = scanout_.plane_id != 0;
        }
        gbm_ = gbm_create_device(fd);
        if (gbm_ == nullptr) fail("gbm_create_device failed on " + device_);
        gbm_surface_ = gbm_surface_create(gbm_, scanout_.mode.hdisplay, scanout_.mode.vdisplay, GBM_FORMAT_XRGB8888,
                                          GBM_BO_USE_SCANOUT | GBM_BO_USE_RENDERING);
        if (gbm_surface_ == nullptr) fail("cannot create a GBM scanout surface");
        auto get_platform_display =
            reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
        if (get_platform_display == nullptr) fail("EGL lacks eglGetPlatformDisplayEXT");
        egl_display_ = get_platform_display(EGL_PLATFORM_GBM_KHR, gbm_, nullptr);
        egl_ = initialise_egl_display(egl_display_, "kms");
        const EGLConfig config = choose_gles3_config(egl_display_, EGL_WINDOW_BIT, GBM_FORMAT_XRGB8888, "kms");
        context_ = create_gles3_context(egl_display_, config, "kms");
        surface_ = eglCreateWindowSurface(egl_display_, config, reinterpret_cast<EGLNativeWindowType>(gbm_surface_), nullptr);
        if (surface_ == EGL_NO_SURFACE) fail(std::string("eglCreateWindowSurface failed (") + egl_error_name(eglGetError()) + ")");
        if (!eglMakeCurrent(egl_display_, surface_, surface_, context_)) fail("eglMakeCurrent failed");
        gl_ = gl_description();
        draw_.create(width(), height(), options_.msaa_samples);
        mode_set_ = false;
    }

    void close_display() {
        const int fd = seat_.fd;
        if (saved_crtc_ != nullptr && fd >= 0) {
            // Give the console back exactly as we found it.
            drmModeSetCrtc(fd, saved_crtc_->crtc_id, saved_crtc_->buffer_id, saved_crtc_->x, saved_crtc_->y,
                           &scanout_.connector_id, 1, &saved_crtc_->mode);
            drmModeFreeCrtc(saved_crtc_);
            saved_crtc_ = nullptr;
        }
        if (egl_display_ != EGL_NO_DISPLAY) {
            const bool current = eglGetCurrentContext() == context_;
            draw_.release(current);
            resolved_.release(current);
            eglMakeCurrent(egl_display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
            if (surface_ != EGL_NO_SURFACE) eglDestroySurface(egl_display_, surface_);
            if (context_ != EGL_NO_CONTEXT) eglDestroyContext(egl_display_, context_);
            eglTerminate(egl_display_);
        }
        surface_ = EGL_NO_SURFACE;
        context_ = EGL_NO_CONTEXT;
        egl_display_ = EGL_NO_DISPLAY;
        if (gbm_surface_ != nullptr) {
            if (front_ != nullptr) gbm_surface_release_buffer(gbm_surface_, front_);
            gbm_surface_destroy(gbm_surface_);
        }
        front_ = nullptr;
        gbm_surface_ = nullptr;
        if (gbm_ != nullptr) gbm_device_destroy(gbm_);
        gbm_ = nullptr;
        if (mode_blob_ != 0 && fd >= 0) drmModeDestroyPropertyBlob(fd, mode_blob_);
        mode_blob_ = 0;
    }

    // The DRM framebuffer of a GBM buffer, created once and kept as its user data.
    std::uint32_t framebuffer_for(gbm_bo* bo) {
        if (void* data = gbm_bo_get_user_data(bo)) return static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(data));
        const int fd = seat_.fd;
        std::uint32_t fb = 0;
        const std::uint32_t handles[4] = {gbm_bo_get_handle(bo).u32, 0, 0, 0};
        const std::uint32_t strides[4] = {gbm_bo_get_stride(bo), 0, 0, 0};
        const std::uint32_t offsets[4] = {0, 0, 0, 0};
        if (drmModeAddFB2(fd, gbm_bo_get_width(bo), gbm_bo_get_height(bo), gbm_bo_get_format(bo), handles, strides,
                          offsets, &fb, 0) != 0)
            return 0;
        gbm_bo_set_user_data(bo, reinterpret_cast<void*>(static_cast<std::uintptr_t>(fb)), [](gbm_bo* b, void* d) {
            const int device_fd = gbm_device_get_fd(gbm_bo_get_device(b));
            drmModeRmFB(device_fd, static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(d)));
        });
        return fb;
    }

    bool add(drmModeAtomicReq* req, std::uint32_t object, std::uint32_t type, const char* name, std::uint64_t value) {
        const std::uint32_t id = property_id(seat_.fd, object, type, name);
        return id != 0 && drmModeAtomicAddProperty(req, object, id, value) > 0;
    }

    bool add_plane(drmModeAtomicReq* req, std::uint32_t fb) {
        const std::uint32_t p = scanout_.plane_id;
        const std::uint64_t w = scanout_.mode.hdisplay;
        const std::uint64_t h = scanout_.mode.vdisplay;
        return add(req, p, DRM_MODE_OBJECT_PLANE, "FB_ID", fb) && add(req, p, DRM_MODE_OBJECT_PLANE, "CRTC_ID", scanout_.crtc_id) &&
               add(req, p, DRM_MODE_OBJECT_PLANE, "SRC_X", 0) && add(req, p, DRM_MODE_OBJECT_PLANE, "SRC_Y", 0) &&
               add(req, p, DRM_MODE_OBJECT_PLANE, "SRC_W", w << 16) && add(req, p, DRM_MODE_OBJECT_PLANE, "SRC_H", h << 16) &&
               add(req, p, DRM_MODE_OBJECT_PLANE, "CRTC_X", 0) && add(req, p, DRM_MODE_OBJECT_PLANE, "CRTC_Y", 0) &&
               add(req, p, DRM_MODE_OBJECT_PLANE, "CRTC_W", w) && add(req, p, DRM_MODE_OBJECT_PLANE, "CRTC_H", h);
    }

    bool set_mode(std::uint32_t fb) {
        const int fd = seat_.fd;
        if (atomic_) {
            drmModeAtomicReq* req = drmModeAtomicAlloc();
            bool ok = drmModeCreatePropertyBlob(fd, &scanout_.mode, sizeof(scanout_.mode), &mode_blob_) == 0 &&
                      add(req, scanout_.connector_id, DRM_MODE_OBJECT_CONNECTOR, "CRTC_ID", scanout_.crtc_id) &&
                      add(req, scanout_.crtc_id, DRM_MODE_OBJECT_CRTC, "MODE_ID", mode_blob_) &&
                      add(req, scanout_.crtc_id, DRM_MODE_OBJECT_CRTC, "ACTIVE", 1) && add_plane(req, fb);
            ok = ok && drmModeAtomicCommit(fd, req, DRM_MODE_ATOMIC_ALLOW_MODESET, nullptr) == 0;
            drmModeAtomicFree(req);
            if (ok) return true;
            atomic_ = false;  // the driver refused: fall back to legacy for good
        }
        return drmModeSetCrtc(fd, scanout_.crtc_id, fb, 0, 0, &scanout_.connector_id, 1, &scanout_.mode) == 0;
    }

    bool flip(std::uint32_t fb) {
        const int fd = seat_.fd;
        flip_pending_ = true;
        if (atomic_) {
            drmModeAtomicReq* req = drmModeAtomicAlloc();
            const bool ok = add(req, scanout_.plane_id, DRM_MODE_OBJECT_PLANE, "FB_ID", fb) &&
                            drmModeAtomicCommit(fd, req, DRM_MODE_PAGE_FLIP_EVENT | DRM_MODE_ATOMIC_NONBLOCK, this) == 0;
            drmModeAtomicFree(req);
            if (ok) return true;
        } else if (drmModePageFlip(fd, scanout_.crtc_id, fb, DRM_MODE_PAGE_FLIP_EVENT, this) == 0) {
            return true;
        }
        flip_pending_ = false;
        return false;
    }

    void wait_for_flip() {
        drmEventContext events{};
        events.version = 2;
        events.page_flip_handler = [](int, unsigned, unsigned tv_sec, unsigned tv_usec, void* self) {
            auto* platform = static_cast<KmsPlatform*>(self);
            platform->flip_pending_ = false;
            // The vblank the flip landed on; DRM stamps it with CLOCK_MONOTONIC
            // (DRM_CAP_TIMESTAMP_MONOTONIC, on every kernel since 3.8).
            platform->flip_time_ns_ = static_cast<std::int64_t>(tv_sec) * 1'000'000'000 +
                                      static_cast<std::int64_t>(tv_usec) * 1'000;
        };
        pollfd p{seat_.fd, POLLIN, 0};
        while (flip_pending_) {
            const int n = poll(&p, 1, 1000);  // a vblank never takes a second: give up then
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) break;
            drmHandleEvent(seat_.fd, &events);
        }
        flip_pending_ = false;
    }

    PlatformOptions options_;
    std::string device_;
    Seat seat_;
    Scanout scanout_;
    drmModeCrtc* saved_crtc_ = nullptr;
    bool atomic_ = false;
    bool mode_set_ = false;
    bool flip_pending_ = false;
    std::int64_t flip_time_ns_ = 0;  // the last page flip's vblank (0: none yet)
    std::uint32_t mode_blob_ = 0;
    gbm_device* gbm_ = nullptr;
    gbm_surface* gbm_surface_ = nullptr;
    gbm_bo* front_ = nullptr;
    EGLDisplay egl_display_ = EGL_NO_DISPLAY;
    EGLContext context_ = EGL_NO_CONTEXT;
    EGLSurface surface_ = EGL_NO_SURFACE;
    RenderTarget draw_;
    RenderTarget resolved_;
    std::string egl_;
    std::string gl_;
};
}  // namespace

std::unique_ptr<Platform> open_kms_platform(const PlatformOptions& options) { return std::make_unique<KmsPlatform>(options); }

}  // namespace marionette::render
