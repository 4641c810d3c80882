#pragma once
// The renderer as the pipeline's render thread drives it: open a platform and a
// renderer once, then per display refresh frame(state, overlay, hud) draws and
// presents. It never touches the simulation: the caller hands it an already
// interpolated copy of the state (interpolate.hpp). A failed present or a lost
// context is reported in the result and recovered by recreating the context and
// every GL resource; only a failed recovery is fatal.
#include <memory>
#include <string>
#include <string_view>

#include "render_es/overlay.hpp"
#include "render_es/platform.hpp"
#include "render_es/renderer.hpp"

namespace marionette::render {

// Drawn over the scene, after the HUD and before present (the tuning UI).
class ViewLayer {
public:
    virtual ~ViewLayer() = default;
    virtual void draw(std::int32_t width, std::int32_t height, float dt_s) = 0;
    // The context was recreated: rebuild every GL name.
    virtual void recreate() = 0;
};

struct FrameResult {
    PresentResult present = PresentResult::ok;
    // When the frame reached the screen (CLOCK_MONOTONIC ns) if the platform knows:
    // the page flip's vblank on KMS; 0 otherwise (a window: the caller stamps after the swap).
    std::int64_t present_ns = 0;
    bool recovered = false;      // the context or surface was rebuilt this frame
    PlatformEvents events;
};

class View {
public:
    // Throws PlatformError or ShaderError.
    // `body`: drawn instead of the capsules when given (Renderer's constructor).
    View(const PlatformOptions& platform, const RenderSettings& settings, const Skeleton& skeleton, const Terrain& terrain,
         const SkinnedMesh* body = nullptr);

    // Polls events (applying the overlay toggles), draws, presents. Throws
    // PlatformError only when recovery from a lost context fails.
    FrameResult frame(const PuppetState& state, const DebugOverlay& overlay, std::string_view hud_text, float dt_s);

    // The last presented frame as a PNG. Throws std::runtime_error.
    void screenshot(const std::string& path);

    // Draws `layer` over every frame from now on (null: none); not owned.
    void set_layer(ViewLayer* layer) { layer_ = layer; }
    Platform& platform() { return *platform_; }
    Renderer& renderer() { return *renderer_; }
    std::uint64_t recoveries() const { return recoveries_; }

private:
    std::unique_ptr<Platform> platform_;
    std::unique_ptr<Renderer> renderer_;
    std::uint64_t recoveries_ = 0;
    ViewLayer* layer_ = nullptr;
    std::vector<std::uint8_t> pixels_;
};

// Heuristic foot markers from a state alone (for logs and sims without a gait
// overlay): each foot's ankle projected to the ground, in contact when the ankle
// is within `contact_height_m` of the ground's height plus the ankle height.
// With a gait rig (the render thread's own, made from the working config), each
// swinging foot also gets its fitted step spline: the path from lift-off to the
// aimed landing as the tick's swing math places it (sample_swing_path,
// runtime/gait/gait.hpp), kOverlaySplinePoints points; the gait toggle draws it.
void feet_overlay_from_state(const PuppetState& state, const Terrain& terrain, float ankle_height_m,
                             DebugOverlay& overlay, const GaitRig* rig = nullptr);

}  // namespace marionette::render
