#pragma once
// Draws one frame of the puppet: terrain, the skinned capsule puppet, debug
// overlays and the text HUD, into whatever framebuffer is bound (the platform's
// begin_frame()). GL resources are built in the constructor from CPU meshes that
// are kept, so recreate() rebuilds them after a context loss. draw() does not
// allocate: bone matrices, line vertices and HUD quads use fixed scratch space.
#include <GLES3/gl3.h>

#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

#include <glm/mat4x4.hpp>

#include "render_es/camera.hpp"
#include "render_es/mesh.hpp"
#include "render_es/overlay.hpp"
#include "render_es/settings.hpp"
#include "runtime/sim/simulation.hpp"

namespace marionette::render {

class Renderer {
public:
    // Needs a current GLES 3 context. Throws ShaderError (naming the shader).
    // `body` (optional, copied): a skinned mesh bound to the skeleton's joints
    // drawn instead of the capsules (a glTF character, character/); it must have
    // one inverse bind per joint. Throws std::invalid_argument when it does not.
    Renderer(const Skeleton& skeleton, const Terrain& terrain, const RenderSettings& settings,
             const SkinnedMesh* body = nullptr);
    ~Renderer();
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    // Rebuilds every GL object in the now-current context; the old names are
    // forgotten, not deleted (their context is gone).
    void recreate();

    void set_terrain(const Terrain& terrain);
    void set_settings(const RenderSettings& settings) { settings_ = settings; }
    const RenderSettings& settings() const { return settings_; }
    OverlayToggles& toggles() { return toggles_; }
    void reset_camera() { camera_.placed = false; }
    const FollowCamera& camera() const { return camera_; }

    // Draws `state` seen by the follow camera, advanced by dt_s seconds.
    void draw(const PuppetState& state, const DebugOverlay& overlay, std::string_view hud_text, std::int32_t width,
              std::int32_t height, float dt_s);

    std::size_t puppet_triangle_count() const { return puppet_.indices.size() / 3; }
    std::size_t terrain_triangle_count() const { return terrain_.indices.size() / 3; }

private:
    struct LineVertex {
        std::array<float, 3> position;
        std::array<float, 3> colour;
    };
    struct HudVertex {  // stb_easy_font's layout: x, y, z, rgba
        float x, y, z;
        std::array<std::uint8_t, 4> colour;
    };

    void create_gl();
    void destroy_gl();
    void upload_terrain();
    void add_line(vec3 a, vec3 b, vec3 colour);
    void add_cross(vec3 p, float size, vec3 colour);
    void add_ring(vec3 centre, float radius, vec3 colour);
    void draw_overlays(const PuppetState& state, const DebugOverlay& overlay, const glm::mat4& view_projection);
    void draw_hud(std::int32_t width, std::int32_t height);  // hud_text_, NUL-terminated

    RenderSettings settings_;
    OverlayToggles toggles_;
    FollowCamera camera_;
    std::vector<int> parents_;
    SkinnedMesh puppet_;
    TerrainMesh terrain_;

    GLuint skinned_program_ = 0, terrain_program_ = 0, line_program_ = 0, hud_program_ = 0;
    GLuint puppet_vao_ = 0, puppet_vbo_ = 0, puppet_ibo_ = 0, bones_ubo_ = 0;
    GLuint terrain_vao_ = 0, terrain_vbo_ = 0, terrain_ibo_ = 0;
    GLuint line_vao_ = 0, line_vbo_ = 0;
    GLuint hud_vao_ = 0, hud_vbo_ = 0, hud_ibo_ = 0;

    std::array<glm::mat4, kMaxBones> bones_{};
    static constexpr std::size_t kMaxLineVertices = 4096;
    std::vector<LineVertex> lines_;          // capacity reserved once
    static constexpr std::size_t kMaxHudQuads = 4096;
    std::vector<HudVertex> hud_vertices_;    // capacity reserved once
    std::array<char, 4096> hud_text_{};
};

}  // namespace marionette::render
