#pragma once
// Dear ImGui's draw lists drawn with OpenGL ES 3.0, on whatever context the
// platform made current (window, KMS or headless).
//
// Our own small renderer backend, written on ImGui's public API (ImDrawData,
// ImFontAtlas) rather than the packaged one: Debian's libimgui-dev 1.86 ships
// imgui_impl_opengl3 built for desktop GL only. It loads its functions from
// libGL.so.1 through glXGetProcAddressARB (no GLX on KMS or a surfaceless
// context) and calls glPolygonMode, which GLES has not. The packaged SDL2
// backend (imgui_impl_sdl) is used as it is for the window's mouse and keys.
#include <GLES3/gl3.h>

struct ImDrawData;

namespace marionette::render {

class ImGuiGles3Renderer {
public:
    // Needs a current GLES 3 context and a current ImGui context (for the font
    // atlas). Throws ShaderError.
    ImGuiGles3Renderer();
    ~ImGuiGles3Renderer();
    ImGuiGles3Renderer(const ImGuiGles3Renderer&) = delete;
    ImGuiGles3Renderer& operator=(const ImGuiGles3Renderer&) = delete;

    // Draws into the bound framebuffer (framebuffer_width × framebuffer_height
    // pixels); leaves blending, culling, depth and scissor as the scene wants them.
    void draw(const ImDrawData& data, int framebuffer_width, int framebuffer_height);
    // After a context loss: every name is rebuilt (the old ones died with it).
    void recreate();

private:
    void create();
    void destroy(bool context_alive);
    GLuint program_ = 0;
    GLint projection_ = -1;
    GLint texture_uniform_ = -1;
    GLuint vao_ = 0;
    GLuint vbo_ = 0;
    GLuint ibo_ = 0;
    GLuint font_ = 0;
};

}  // namespace marionette::render
