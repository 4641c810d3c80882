#include "app/live_view.hpp"

#include <fmt/format.h>

#include "render_es/interpolate.hpp"
#include "runtime/import_error.hpp"

namespace marionette {

std::unique_ptr<LiveView> LiveView::open(const std::string& display, const std::string& render_config_file,
                                         const Simulation& sim) {
    render::PlatformRequest request = render::PlatformRequest::automatic;
    if (display == "headless") request = render::PlatformRequest::headless;
    else if (display == "window") request = render::PlatformRequest::window;
    else if (display == "kms") request = render::PlatformRequest::kms;
    else if (display != "auto")
        throw ImportError("--display", 0, "expected auto, headless, window or kms, got '" + display + "'");
    const render::PlatformKind kind = render::select_platform(request, render::detect_display_environment());
    if (kind == render::PlatformKind::headless) return nullptr;

    std::unique_ptr<LiveView> live(new LiveView);
    live->config_ = load_render_config(render_config_file);
    render::PlatformOptions options;
    options.kind = kind;
    options.width = live->config_.settings.width;
    options.height = live->config_.settings.height;
    options.msaa_samples = live->config_.settings.msaa_samples;
    options.vsync = live->config_.settings.vsync;
    options.fullscreen = live->config_.settings.fullscreen;
    options.drm_device = live->config_.drm_device;
    options.kms_mode = live->config_.kms;
    live->terrain_ = &sim.terrain();
    live->ankle_height_ = sim.config().ankle_height;
    live->view_ = std::make_unique<render::View>(options, live->config_.settings, sim.skeleton(), sim.terrain());
    return live;
}

bool LiveView::frame(const PuppetState& previous, const PuppetState& current, float alpha, const std::string& hud) {
    const auto now = std::chrono::steady_clock::now();
    if (frames_ > 0 && now - last_frame_ < frame_interval_) return true;
    const float dt = frames_ == 0 ? 0.0f : std::chrono::duration<float>(now - last_frame_).count();
    last_frame_ = now;
    render::interpolate_state(previous, current, alpha, drawn_);
    render::feet_overlay_from_state(drawn_, *terrain_, ankle_height_, overlay_);
    const render::FrameResult r = view_->frame(drawn_, overlay_, hud, dt);
    ++frames_;
    if (r.recovered) fmt::print(stderr, "warning: the display context was lost; recreated it and every GL resource\n");
    if (r.events.screenshot_requested) {
        const std::string path = fmt::format("marionette-screenshot-{:03d}.png", ++screenshots_);
        view_->screenshot(path);
        fmt::print("screenshot: {}\n", path);
    }
    return !r.events.close_requested;
}

}  // namespace marionette
