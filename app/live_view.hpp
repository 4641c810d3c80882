#pragma once
// The display `marionette run` draws on (window or KMS): opened on the main thread
// (so a failure is an ordinary error with its exit code), then handed to the
// pipeline's render thread (app/pipeline.hpp), which calls frame() once per
// display refresh with the two latest ticks and the interpolation alpha. Closing
// the window (or Esc) sets the run's stop flag, as Ctrl-C does.
#include <array>
#include <atomic>
#include <memory>
#include <string>

#include "app/render_config.hpp"
#include "render_es/view.hpp"
#include "runtime/simulation.hpp"

namespace marionette {

class LiveView {
public:
    // display: auto|headless|window|kms. Returns nullptr when the choice is headless
    // (no display: the run stays a console program). Throws render::PlatformError,
    // render::ShaderError, ConfigError.
    static std::unique_ptr<LiveView> open(const std::string& display, const std::string& render_config_file,
                                          const SimConfig& config, std::atomic<bool>* stop_flag);
    ~LiveView();

    // Draws previous→current at alpha with a status HUD; handles the window's keys
    // (overlays, screenshot) and close. No allocation (unless a screenshot is taken).
    void frame(const PuppetState& previous, const PuppetState& current, float alpha);
    // Called by the render thread when it ends, so the main thread can free the context.
    void release_thread() { view_->platform().release_current(); }

    std::string description() { return view_->platform().description(); }
    std::uint64_t frames() const { return frames_; }

private:
    LiveView() = default;
    RenderConfig config_;
    std::unique_ptr<Simulation> skeleton_source_;  // skeleton and terrain of the run's configuration
    std::unique_ptr<render::View> view_;
    std::atomic<bool>* stop_flag_ = nullptr;
    float ankle_height_ = 0.0f;
    double tick_rate_ = 240.0;
    PuppetState drawn_;
    render::DebugOverlay overlay_;
    std::array<char, 256> hud_{};
    std::int64_t last_frame_ns_ = 0;
    std::uint64_t frames_ = 0;
    int screenshots_ = 0;
};

}  // namespace marionette
