#include "app/live_view.hpp"

#include <fmt/format.h>

#include <chrono>

#include "render_es/interpolate.hpp"
#include "runtime/import_error.hpp"

namespace marionette {

std::unique_ptr<LiveView> LiveView::open(const std::string& display, const std::string& render_config_file,
                                         const SimConfig& config, std::atomic<bool>* stop_flag) {
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
    live->skeleton_source_ = std::make_unique<Simulation>(config);
    live->stop_flag_ = stop_flag;
    live->ankle_height_ = config.ankle_height;
    live->tick_rate_ = config.tick_rate_hz;
    live->view_ = std::make_unique<render::View>(options, live->config_.settings, live->skeleton_source_->skeleton(),
                                                 live->skeleton_source_->terrain());
    live->view_->platform().release_current();  // the render thread takes it
    return live;
}

LiveView::~LiveView() {
    // Take the context back so the renderer's GL objects are freed in it.
    if (view_) view_->platform().begin_frame();
}

void LiveView::frame(const PuppetState& previous, const PuppetState& current, float alpha) {
    const std::int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                 std::chrono::steady_clock::now().time_since_epoch()).count();
    const float dt = frames_ == 0 ? 0.0f : static_cast<float>(now - last_frame_ns_) * 1e-9f;
    last_frame_ns_ = now;
    render::interpolate_state(previous, current, alpha, drawn_);
    render::feet_overlay_from_state(drawn_, skeleton_source_->terrain(), ankle_height_, overlay_);
    const float speed = std::sqrt(drawn_.velocity.x * drawn_.velocity.x + drawn_.velocity.y * drawn_.velocity.y);
    const auto written = fmt::format_to_n(hud_.data(), hud_.size(), "t {:.2f} s  tick {}  speed {:.2f} m/s  {:.0f} fps",
                                          static_cast<double>(drawn_.tick) / tick_rate_, drawn_.tick, speed,
                                          dt > 0.0f ? 1.0f / dt : 0.0f);
    const render::FrameResult r =
        view_->frame(drawn_, overlay_, std::string_view(hud_.data(), std::min(written.size, hud_.size())), dt);
    ++frames_;
    if (r.recovered) fmt::print(stderr, "warning: the display context was lost; recreated it and every GL resource\n");
    if (r.events.screenshot_requested) {
        const std::string path = fmt::format("marionette-screenshot-{:03d}.png", ++screenshots_);
        view_->screenshot(path);
        fmt::print("screenshot: {}\n", path);
    }
    if (r.events.close_requested && stop_flag_ != nullptr) stop_flag_->store(true);
}

}  // namespace marionette
