#pragma once
// EGL steps the headless and KMS platforms share: initialise a display, choose a
// GLES 3 config, create a GLES 3.0 context. Errors are PlatformError naming the
// step and the EGL error.
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdint>
#include <string>

namespace marionette::render {

// eglInitialize + eglBindAPI(GLES); returns "EGL 1.5 (Mesa Project)".
std::string initialise_egl_display(EGLDisplay display, const char* platform);

// A config renderable with GLES 3 for `surface_type` (EGL_WINDOW_BIT, or 0 for
// surfaceless). When native_visual != 0 the config's EGL_NATIVE_VISUAL_ID must match
// it (GBM formats). Throws PlatformError.
EGLConfig choose_gles3_config(EGLDisplay display, EGLint surface_type, EGLint native_visual, const char* platform);

// A GLES 3.0 context (robust with reset notification when the driver offers it, so
// context loss is reported instead of crashing). Throws PlatformError.
EGLContext create_gles3_context(EGLDisplay display, EGLConfig config, const char* platform);

// "OpenGL ES 3.2 Mesa 22.3.6, llvmpipe (LLVM 15.0.6, 256 bits)" for the current context.
std::string gl_description();

// True when the display's extension string lists `name`.
bool egl_has_extension(EGLDisplay display, const char* name);

}  // namespace marionette::render
