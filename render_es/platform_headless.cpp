// Headless platform: a surfaceless EGL context (EGL_MESA_platform_surfaceless,
// else the first EGL_EXT_platform_device device) drawing into an FBO. Used for
// tests, screenshots, offline frames and video; works on llvmpipe and real GPUs.
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLES3/gl3.h>

#include <cstring>

#include "render_es/egl_util.hpp"
#include "render_es/gl_util.hpp"
#include "render_es/platform.hpp"

namespace marionette::render {

namespace {
constexpr GLenum kGlContextLost = 0x0507;  // GL_CONTEXT_LOST (GLES 3.2 / KHR_robustness)

EGLDisplay surfaceless_display(std::string& which) {
    const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    auto has = [client](const char* name) { return client != nullptr && std::strstr(client, name) != nullptr; };
    auto get_platform_display =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (get_platform_display == nullptr) throw PlatformError("headless platform: EGL lacks eglGetPlatformDisplayEXT");
    if (has("EGL_MESA_platform_surfaceless")) {
        which = "surfaceless";
        return get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    }
    if (has("EGL_EXT_platform_device")) {
        auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
        EGLDeviceEXT devices[8];
        EGLint count = 0;
        if (query_devices != nullptr && query_devices(8, devices, &count) && count > 0) {
            which = "device";
            return get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[0], nullptr);
        }
    }
    throw PlatformError(
        "headless platform: EGL offers neither EGL_MESA_platform_surfaceless nor EGL_EXT_platform_device "
        "(install libegl-mesa0 for Mesa's llvmpipe)");
}

class HeadlessPlatform final : public Platform {
public:
    explicit HeadlessPlatform(const PlatformOptions& options) : options_(options) {
        if (options.width <= 0 || options.height <= 0 || options.width > 16384 || options.height > 16384)
            throw PlatformError("headless platform: size " + std::to_string(options.width) + "x" +
                                std::to_string(options.height) + " is out of range (1..16384)");
        display_ = surfaceless_display(which_);
        egl_ = initialise_egl_display(display_, "headless");
        create_context();
    }

    ~HeadlessPlatform() override {
        release_context();
        if (display_ != EGL_NO_DISPLAY) eglTerminate(display_);
    }

    PlatformKind kind() const override { return PlatformKind::headless; }
    std::int32_t width() const override { return options_.width; }
    std::int32_t height() const override { return options_.height; }

    void begin_frame() override {
        if (eglGetCurrentContext() != context_) eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_);
        glBindFramebuffer(GL_FRAMEBUFFER, draw_.framebuffer);
        glViewport(0, 0, options_.width, options_.height);
    }

    PresentResult present() override {
        draw_.resolve_to(resolved_.framebuffer, resolved_.width, resolved_.height);
        // Only a lost context is a failed present here; other GL errors are bugs
        // in a draw call, not something recreating the context would fix.
        return glGetError() == kGlContextLost ? PresentResult::context_lost : PresentResult::ok;
    }

    void release_current() override { eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT); }

    PlatformEvents poll_events() override { return {}; }

    bool recover() override { return rebuild([this] { release_context(); }, [this] { create_context(); }); }

    void read_pixels(std::vector<std::uint8_t>& rgba) override {
        read_rgba_top_down(resolved_.framebuffer, options_.width, options_.height, rgba);
    }

    std::string description() const override { return "headless (" + which_ + ") " + egl_ + ", " + gl_; }

private:
    void create_context() {
        const EGLConfig config = choose_gles3_config(display_, 0, 0, "headless");
        context_ = create_gles3_context(display_, config, "headless");
        if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
            throw PlatformError(std::string("headless platform: eglMakeCurrent without a surface failed (") +
                                egl_error_name(eglGetError()) + ")");
        gl_ = gl_description();
        draw_.create(options_.width, options_.height, options_.msaa_samples);
        resolved_.create(options_.width, options_.height, 0);
    }

    void release_context() {
        if (context_ == EGL_NO_CONTEXT) return;
        const bool current = eglGetCurrentContext() == context_;
        draw_.release(current);
        resolved_.release(current);
        eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(display_, context_);
        context_ = EGL_NO_CONTEXT;
    }

    PlatformOptions options_;
    EGLDisplay display_ = EGL_NO_DISPLAY;
    EGLContext context_ = EGL_NO_CONTEXT;
    RenderTarget draw_;
    RenderTarget resolved_;
    std::string which_;
    std::string egl_;
    std::string gl_;
};
}  // namespace

std::unique_ptr<Platform> open_headless_platform(const PlatformOptions& options) {
    return std::make_unique<HeadlessPlatform>(options);
}

}  // namespace marionette::render
