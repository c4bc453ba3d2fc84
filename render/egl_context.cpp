#include "render/egl_context.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <GL/glext.h>

#include <cstring>

namespace nadir::render {
namespace {

std::string eglErrorText() {
  const EGLint code = eglGetError();
  switch (code) {
    case EGL_SUCCESS:
      return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    default:
      return "EGL error " + std::to_string(code);
  }
}

std::string text(const char* value) { return value != nullptr ? value : ""; }

bool hasExtension(const char* extensions, const char* name) {
  if (extensions == nullptr) return false;
  const std::size_t length = std::strlen(name);
  for (const char* at = std::strstr(extensions, name); at != nullptr;
       at = std::strstr(at + 1, name)) {
    const bool starts = at == extensions || at[-1] == ' ';
    const bool ends = at[length] == '\0' || at[length] == ' ';
    if (starts && ends) return true;
  }
  return false;
}

// Core EGL 1.5 first; GLVND's libEGL does not export the EXT variant for
// linking, so fetch that one through eglGetProcAddress.
EGLDisplay surfacelessDisplay() {
  EGLDisplay display =
      eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (display != EGL_NO_DISPLAY) return display;
  auto get_display_ext = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (get_display_ext == nullptr) return EGL_NO_DISPLAY;
  return get_display_ext(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
}

}  // namespace

struct HeadlessGlContext::Egl {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
};

HeadlessGlContext::HeadlessGlContext(int major, int minor) : egl_(std::make_unique<Egl>()) {
  const char* client_extensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!hasExtension(client_extensions, "EGL_MESA_platform_surfaceless")) {
    throw GlContextError(
        "EGL has no surfaceless Mesa platform (EGL_MESA_platform_surfaceless): install "
        "libegl1 and libgl1-mesa-dri (apt-get install libegl1 libgl1-mesa-dri)");
  }
  egl_->display = surfacelessDisplay();
  if (egl_->display == EGL_NO_DISPLAY) {
    throw GlContextError("eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA) failed: " +
                         eglErrorText());
  }
  EGLint egl_major = 0, egl_minor = 0;
  if (eglInitialize(egl_->display, &egl_major, &egl_minor) != EGL_TRUE) {
    throw GlContextError("eglInitialize on the surfaceless platform failed (" + eglErrorText() +
                         "): Mesa's drivers are missing; apt-get install libgl1-mesa-dri");
  }
  info_.egl_version = text(eglQueryString(egl_->display, EGL_VERSION));
  info_.egl_vendor = text(eglQueryString(egl_->display, EGL_VENDOR));

  // Surfaceless rendering goes to framebuffer objects; pbuffer configs are the ones offered.
  const EGLint config_attributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE,
                                      EGL_OPENGL_BIT, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint config_count = 0;
  if (eglChooseConfig(egl_->display, config_attributes, &config, 1, &config_count) != EGL_TRUE ||
      config_count < 1) {
    eglTerminate(egl_->display);
    throw GlContextError("no EGL config renders desktop OpenGL (" + eglErrorText() + ")");
  }
  if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) {
    eglTerminate(egl_->display);
    throw GlContextError("eglBindAPI(EGL_OPENGL_API) failed: " + eglErrorText());
  }
  const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                                       major,
                                       EGL_CONTEXT_MINOR_VERSION,
                                       minor,
                                       EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                       EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                       EGL_NONE};
  egl_->context = eglCreateContext(egl_->display, config, EGL_NO_CONTEXT, context_attributes);
  if (egl_->context == EGL_NO_CONTEXT) {
    eglTerminate(egl_->display);
    throw GlContextError("cannot create an OpenGL " + std::to_string(major) + "." +
                         std::to_string(minor) + " core context (" + eglErrorText() + ")");
  }
  makeCurrent();
  info_.gl_vendor = text(reinterpret_cast<const char*>(glGetString(GL_VENDOR)));
  info_.gl_renderer = text(reinterpret_cast<const char*>(glGetString(GL_RENDERER)));
  info_.gl_version = text(reinterpret_cast<const char*>(glGetString(GL_VERSION)));
  info_.glsl_version =
      text(reinterpret_cast<const char*>(glGetString(GL_SHADING_LANGUAGE_VERSION)));
  glGetIntegerv(GL_MAJOR_VERSION, &info_.gl_major);
  glGetIntegerv(GL_MINOR_VERSION, &info_.gl_minor);
  GLint profile_mask = 0;
  glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile_mask);
  info_.core_profile = (profile_mask & GL_CONTEXT_CORE_PROFILE_BIT) != 0;
}

HeadlessGlContext::~HeadlessGlContext() {
  eglMakeCurrent(egl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(egl_->display, egl_->context);
  eglTerminate(egl_->display);
}

void HeadlessGlContext::makeCurrent() {
  if (eglMakeCurrent(egl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, egl_->context) != EGL_TRUE) {
    throw GlContextError("eglMakeCurrent without a surface failed (" + eglErrorText() +
                         "): EGL_KHR_surfaceless_context is needed");
  }
}

}  // namespace nadir::render
