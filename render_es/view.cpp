#include "render_es/view.hpp"

#include <span>

#include "render_es/image.hpp"
#include "runtime/gait/gait.hpp"
#include "runtime/gait/puppet.hpp"

namespace marionette::render {

View::View(const PlatformOptions& platform, const RenderSettings& settings, const Skeleton& skeleton,
           const Terrain& terrain, const SkinnedMesh* body)
    : platform_(open_platform(platform)) {
    platform_->begin_frame();
    renderer_ = std::make_unique<Renderer>(skeleton, terrain, settings, body);
}

FrameResult View::frame(const PuppetState& state, const DebugOverlay& overlay, std::string_view hud_text, float dt_s) {
    FrameResult result;
    result.events = platform_->poll_events();
    OverlayToggles& t = renderer_->toggles();
    if (result.events.toggle_skeleton) t.skeleton = !t.skeleton;
    if (result.events.toggle_feet) t.feet = !t.feet;
    if (result.events.toggle_gait) t.gait = !t.gait;
    if (result.events.toggle_motion_graph) t.motion_graph = !t.motion_graph;
    if (result.events.toggle_hud) t.hud = !t.hud;

    platform_->begin_frame();
    renderer_->draw(state, overlay, hud_text, platform_->width(), platform_->height(), dt_s);
    if (layer_ != nullptr) layer_->draw(platform_->width(), platform_->height(), dt_s);
    result.present = platform_->present();
    result.present_ns = result.present == PresentResult::ok ? platform_->last_present_ns() : 0;
    if (result.present != PresentResult::ok) {
        // Rebuild the context and everything in it; the next frame draws normally.
        if (!platform_->recover())
            throw PlatformError(std::string(platform_name(platform_->kind())) +
                                " platform: the context was lost and could not be recreated");
        platform_->begin_frame();
        renderer_->recreate();
        if (layer_ != nullptr) layer_->recreate();
        result.recovered = true;
        ++recoveries_;
    }
    return result;
}

void View::screenshot(const std::string& path) {
    platform_->read_pixels(pixels_);
    Image image;
    image.width = platform_->width();
    image.height = platform_->height();
    image.rgba = pixels_;
    write_png(path, image);
}

void feet_overlay_from_state(const PuppetState& state, const Terrain& terrain, float ankle_height_m,
                             DebugOverlay& overlay, const GaitRig* rig) {
    if (state.joint_count < kPuppetJointCount) {
        overlay.foot_count = 0;
        return;
    }
    overlay.foot_count = 2;
    const int ankles[2] = {kFootL, kFootR};
    for (int f = 0; f < 2; ++f) {
        const vec3 ankle = state.model_positions[static_cast<std::size_t>(ankles[f])];
        const GroundSample ground = query_ground(terrain, ankle.x, ankle.z);
        FootOverlay& foot = overlay.feet[static_cast<std::size_t>(f)];
        foot.position = ankle;
        foot.target = vec3(ankle.x, ground.height, ankle.z);
        foot.in_contact = ankle.y - ground.height < ankle_height_m + 0.02f;
        foot.spline_points = 0;
        const FootState& gait_foot = state.gait.feet[static_cast<std::size_t>(f)];
        if (rig != nullptr && gait_foot.swinging)
            foot.spline_points = sample_swing_path(gait_foot, f, *rig, state.gait.run_blend, state.gait_root.heading,
                                                   std::span<vec3>(foot.spline.data(), foot.spline.size()));
    }
}

}  // namespace marionette::render
