#pragma once
// Small GLES 3 helpers shared by the platforms and the renderer: shader programs
// whose compile/link errors name the shader and carry its log, and an offscreen
// render target (optionally multisampled) that resolves into another framebuffer.
#include <GLES3/gl3.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace marionette::render {

// A shader failed to compile or link: what() is "shader NAME (vertex): LOG".
class ShaderError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Compiles and links a program; throws ShaderError naming `name` and the stage.
GLuint build_program(const std::string& name, const char* vertex_source, const char* fragment_source);

// Name of a GL error code, e.g. "GL_INVALID_OPERATION".
const char* gl_error_name(GLenum error);
// Name of an EGL error code, e.g. "EGL_BAD_ALLOC" (as an int, so no EGL header here).
const char* egl_error_name(std::int32_t error);

// An FBO with colour + depth renderbuffers, `samples` > 1 for MSAA. resolve_to()
// blits it into `target` (0 = the surface's default framebuffer).
struct RenderTarget {
    GLuint framebuffer = 0;
    GLuint colour = 0;
    GLuint depth = 0;
    std::int32_t width = 0;
    std::int32_t height = 0;
    std::int32_t samples = 0;

    // Throws std::runtime_error when the FBO is incomplete.
    void create(std::int32_t width, std::int32_t height, std::int32_t samples);
    void destroy();
    // Forgets the GL names without deleting them (their context is gone).
    void abandon() { *this = RenderTarget{}; }
    // destroy() while the target's context is current on this thread, else
    // abandon(): the context is gone or another thread's, so its names cannot be deleted here.
    void release(bool context_current) {
        if (context_current) destroy();
        else abandon();
    }
    void resolve_to(GLuint target, std::int32_t target_width, std::int32_t target_height) const;
    // Resolves into `single` (single-sample RGBA8 of width × height, (re)created as needed).
    void resolve_to_single(RenderTarget& single, std::int32_t single_width, std::int32_t single_height) const;
    // Copies the frame to `target` (a window's framebuffer 0): a multisampled
    // target resolves into `single` (same RGBA8 format, (re)created as needed)
    // first, since GLES forbids a multisample resolve into a different format.
    void present_to(GLuint target, std::int32_t target_width, std::int32_t target_height, RenderTarget& single) const;
};

// Reads `framebuffer` (single-sample RGBA8, width × height) into `rgba`, top
// row first (GL's first row is the bottom one; images start at the top).
void read_rgba_top_down(GLuint framebuffer, std::int32_t width, std::int32_t height, std::vector<std::uint8_t>& rgba);

// Clamps a requested MSAA sample count to what the context supports (0 = off).
std::int32_t supported_samples(std::int32_t requested);

}  // namespace marionette::render
