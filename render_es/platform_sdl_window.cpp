// Window platform: an SDL2 window with an OpenGL ES 3.0 context through EGL (SDL
// is told to use EGL on X11 too), vsync on, resizable, optional fullscreen, for
// desktops and handhelds under Wayland or X11. With MSAA the frame is drawn into
// an FBO (multisampled when asked) and blitted into the window's back buffer.
#include <SDL2/SDL.h>
#include <GLES3/gl3.h>

#include "render_es/egl_util.hpp"
#include "render_es/gl_util.hpp"
#include "render_es/platform.hpp"

namespace marionette::render {

namespace {
constexpr GLenum kGlContextLost = 0x0507;

class SdlWindowPlatform final : public Platform {
public:
    explicit SdlWindowPlatform(const PlatformOptions& options) : options_(options) {
        SDL_SetHint(SDL_HINT_VIDEO_X11_FORCE_EGL, "1");
        SDL_SetHint(SDL_HINT_OPENGL_ES_DRIVER, "1");
        if (SDL_InitSubSystem(SDL_INIT_VIDEO) != 0)
            throw PlatformError(std::string("window platform: SDL video init failed: ") + SDL_GetError());
        SDL_GL_SetAttribute(SDL_GL_CONTEXT_PROFILE_MASK, SDL_GL_CONTEXT_PROFILE_ES);
        SDL_GL_SetAttribute(SDL_GL_CONTEXT_MAJOR_VERSION, 3);
        SDL_GL_SetAttribute(SDL_GL_CONTEXT_MINOR_VERSION, 0);
        SDL_GL_SetAttribute(SDL_GL_DEPTH_SIZE, 24);
        SDL_GL_SetAttribute(SDL_GL_DOUBLEBUFFER, 1);
        Uint32 flags = SDL_WINDOW_OPENGL | SDL_WINDOW_RESIZABLE | SDL_WINDOW_ALLOW_HIGHDPI;
        if (options.fullscreen) flags |= SDL_WINDOW_FULLSCREEN_DESKTOP;
        window_ = SDL_CreateWindow(options.title.c_str(), SDL_WINDOWPOS_CENTERED, SDL_WINDOWPOS_CENTERED, options.width,
                                   options.height, flags);
        if (window_ == nullptr) {
            const std::string error = SDL_GetError();
            SDL_QuitSubSystem(SDL_INIT_VIDEO);
            throw PlatformError("window platform: cannot create a window: " + error);
        }
        try {
            create_context();
        } catch (...) {
            SDL_DestroyWindow(window_);
            SDL_QuitSubSystem(SDL_INIT_VIDEO);
            throw;
        }
    }

    ~SdlWindowPlatform() override {
        release_context();
        SDL_DestroyWindow(window_);
        SDL_QuitSubSystem(SDL_INIT_VIDEO);
    }

    PlatformKind kind() const override { return PlatformKind::window; }
    std::int32_t width() const override { return width_; }
    std::int32_t height() const override { return height_; }

    void begin_frame() override {
        if (SDL_GL_GetCurrentContext() != context_) SDL_GL_MakeCurrent(window_, context_);
        if (draw_.width != width_ || draw_.height != height_) resize_target();
        glBindFramebuffer(GL_FRAMEBUFFER, draw_.framebuffer);
        glViewport(0, 0, width_, height_);
    }

    PresentResult present() override {
        draw_.present_to(0, width_, height_, resolved_);
        SDL_GL_SwapWindow(window_);  // blocks until vblank with vsync: this is the pacing
        return glGetError() == kGlContextLost ? PresentResult::context_lost : PresentResult::ok;
    }

    void release_current() override { SDL_GL_MakeCurrent(window_, nullptr); }

    PlatformEvents poll_events() override {
        PlatformEvents e;
        SDL_Event event;
        while (SDL_PollEvent(&event)) {
            if (event.type == SDL_QUIT) e.close_requested = true;
            if (hook_ != nullptr && hook_->on_native_event(&event)) continue;
            if (event.type == SDL_WINDOWEVENT && event.window.event == SDL_WINDOWEVENT_SIZE_CHANGED) e.resized = true;
            if (event.type == SDL_KEYDOWN && event.key.repeat == 0) {
                switch (event.key.keysym.sym) {
                    case SDLK_ESCAPE: e.close_requested = true; break;
                    case SDLK_F12:
                    case SDLK_p: e.screenshot_requested = true; break;
                    case SDLK_1: e.toggle_skeleton = true; break;
                    case SDLK_2: e.toggle_feet = true; break;
                    case SDLK_3: e.toggle_gait = true; break;
                    case SDLK_4: e.toggle_motion_graph = true; break;
                    case SDLK_h: e.toggle_hud = true; break;
                    case SDLK_F11: {
                        const bool full = (SDL_GetWindowFlags(window_) & SDL_WINDOW_FULLSCREEN_DESKTOP) != 0;
                        SDL_SetWindowFullscreen(window_, full ? 0 : SDL_WINDOW_FULLSCREEN_DESKTOP);
                        break;
                    }
                    default: break;
                }
            }
        }
        if (e.resized) SDL_GL_GetDrawableSize(window_, &width_, &height_);
        return e;
    }

    bool recover() override { return rebuild([this] { release_context(); }, [this] { create_context(); }); }

    void read_pixels(std::vector<std::uint8_t>& rgba) override {
        // The window's back buffer is undefined after the swap; the frame is still
        // in the draw target, so resolve that into a single-sample copy and read it.
        draw_.resolve_to_single(resolved_, width_, height_);
        read_rgba_top_down(resolved_.framebuffer, width_, height_, rgba);
    }

    void* native_window() const override { return window_; }
    void* native_context() const override { return context_; }
    std::string description() const override {
        return std::string("window (SDL ") + SDL_GetCurrentVideoDriver() + ", vsync " + (vsync_ ? "on" : "off") + "), " + gl_;
    }

private:
    void create_context() {
        context_ = SDL_GL_CreateContext(window_);
        if (context_ == nullptr)
            throw PlatformError(std::string("window platform: cannot create an OpenGL ES 3.0 context: ") + SDL_GetError());
        SDL_GL_MakeCurrent(window_, context_);
        // Adaptive vsync first (late frames tear instead of halving the rate), then plain vsync.
        vsync_ = options_.vsync && (SDL_GL_SetSwapInterval(-1) == 0 || SDL_GL_SetSwapInterval(1) == 0);
        if (!options_.vsync) SDL_GL_SetSwapInterval(0);
        SDL_GL_GetDrawableSize(window_, &width_, &height_);
        gl_ = gl_description();
        resize_target();
    }

    // Frames are drawn into an FBO (multisampled when asked) and blitted to the
    // window on present, so screenshots can read the frame after the swap.
    void resize_target() { draw_.create(width_, height_, options_.msaa_samples); }

    void release_context() {
        if (context_ == nullptr) return;
        const bool current = SDL_GL_GetCurrentContext() == context_;
        draw_.release(current);
        resolved_.release(current);
        SDL_GL_DeleteContext(context_);
        context_ = nullptr;
    }

    PlatformOptions options_;
    SDL_Window* window_ = nullptr;
    SDL_GLContext context_ = nullptr;
    RenderTarget draw_;
    RenderTarget resolved_;
    int width_ = 0;
    int height_ = 0;
    bool vsync_ = false;
    std::string gl_;
};
}  // namespace

std::unique_ptr<Platform> open_window_platform(const PlatformOptions& options) {
    return std::make_unique<SdlWindowPlatform>(options);
}

}  // namespace marionette::render
