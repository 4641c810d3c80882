#include "render_es/egl_util.hpp"

#include <GLES3/gl3.h>

#include <cstring>

#include "render_es/gl_util.hpp"
#include "render_es/platform.hpp"

namespace marionette::render {

namespace {
[[noreturn]] void fail(const char* platform, const std::string& what) {
    throw PlatformError(std::string(platform) + " platform: " + what + " failed (" + egl_error_name(eglGetError()) + ")");
}

bool has_word(const char* list, const char* word) {
    if (list == nullptr) return false;
    const size_t n = std::strlen(word);
    for (const char* p = std::strstr(list, word); p != nullptr; p = std::strstr(p + 1, word))
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
    return false;
}
}  // namespace

bool egl_has_extension(EGLDisplay display, const char* name) {
    return has_word(eglQueryString(display, EGL_EXTENSIONS), name);
}

std::string initialise_egl_display(EGLDisplay display, const char* platform) {
    if (display == EGL_NO_DISPLAY) fail(platform, "getting an EGL display");
    EGLint major = 0;
    EGLint minor = 0;
    if (!eglInitialize(display, &major, &minor)) fail(platform, "eglInitialize");
    if (!eglBindAPI(EGL_OPENGL_ES_API)) fail(platform, "eglBindAPI(EGL_OPENGL_ES_API)");
    const char* vendor = eglQueryString(display, EGL_VENDOR);
    return "EGL " + std::to_string(major) + "." + std::to_string(minor) + " (" + (vendor ? vendor : "?") + ")";
}

EGLConfig choose_gles3_config(EGLDisplay display, EGLint surface_type, EGLint native_visual, const char* platform) {
    const EGLint attributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_ES3_BIT, EGL_SURFACE_TYPE, surface_type,
                                 EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8,
                                 EGL_DEPTH_SIZE, surface_type ? 24 : 0, EGL_NONE};
    EGLConfig configs[64];
    EGLint count = 0;
    if (!eglChooseConfig(display, attributes, configs, 64, &count)) fail(platform, "eglChooseConfig");
    for (EGLint i = 0; i < count; ++i) {
        if (native_visual == 0) return configs[i];
        EGLint id = 0;
        if (eglGetConfigAttrib(display, configs[i], EGL_NATIVE_VISUAL_ID, &id) && id == native_visual) return configs[i];
    }
    throw PlatformError(std::string(platform) + " platform: no EGL config renders OpenGL ES 3 (RGB8" +
                        (native_visual ? ", matching the scanout format" : "") + ")");
}

EGLContext create_gles3_context(EGLDisplay display, EGLConfig config, const char* platform) {
    if (egl_has_extension(display, "EGL_EXT_create_context_robustness")) {
        const EGLint robust[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 0,
                                 EGL_CONTEXT_OPENGL_RESET_NOTIFICATION_STRATEGY_EXT, EGL_LOSE_CONTEXT_ON_RESET_EXT,
                                 EGL_NONE};
        const EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, robust);
        if (context != EGL_NO_CONTEXT) return context;
    }
    const EGLint plain[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 0, EGL_NONE};
    const EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, plain);
    if (context == EGL_NO_CONTEXT) fail(platform, "creating an OpenGL ES 3.0 context");
    return context;
}

std::string gl_description() {
    auto text = [](GLenum name) {
        const GLubyte* s = glGetString(name);
        return s ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
    };
    return text(GL_VERSION) + ", " + text(GL_RENDERER);
}

}  // namespace marionette::render
