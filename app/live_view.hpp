#pragma once
// The renderer inside `marionette run` (window or KMS display): opens the
// platform `--display` names (auto picks one, render_es/platform.hpp), and on each
// loop pass draws the state interpolated between the last two ticks when a
// display refresh is due. Until the pipeline issue moves it to its own thread it
// runs on the simulation's thread between ticks.
#include <chrono>
#include <memory>
#include <string>

#include "app/render_config.hpp"
#include "render_es/view.hpp"
#include "runtime/simulation.hpp"

namespace marionette {

class LiveView {
public:
    // display: auto|headless|window|kms. Returns nullptr when the choice is headless
    // (no display: the run stays a console program). Throws render::PlatformError.
    static std::unique_ptr<LiveView> open(const std::string& display, const std::string& render_config_file,
                                          const Simulation& sim);

    // Draws previous→current at alpha when a frame is due; false once the user
    // closed the window (or pressed Esc).
    bool frame(const PuppetState& previous, const PuppetState& current, float alpha, const std::string& hud);

    std::string description() { return view_->platform().description(); }
    std::uint64_t frames() const { return frames_; }

private:
    LiveView() = default;
    RenderConfig config_;
    std::unique_ptr<render::View> view_;
    const Terrain* terrain_ = nullptr;
    float ankle_height_ = 0.0f;
    PuppetState drawn_;
    render::DebugOverlay overlay_;
    std::chrono::steady_clock::time_point last_frame_{};
    std::chrono::nanoseconds frame_interval_{16'666'667};
    std::uint64_t frames_ = 0;
    int screenshots_ = 0;
};

}  // namespace marionette
