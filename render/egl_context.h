#pragma once
// A headless OpenGL context: EGL on Mesa's surfaceless platform, no display,
// no window, no GPU needed (llvmpipe renders on the CPU).

#include <memory>
#include <stdexcept>
#include <string>

namespace nadir::render {

class GlContextError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct GlContextInfo {
  std::string egl_version;
  std::string egl_vendor;
  std::string gl_vendor;
  std::string gl_renderer;
  std::string gl_version;
  std::string glsl_version;
  int gl_major = 0;
  int gl_minor = 0;
  bool core_profile = false;
};

class HeadlessGlContext {
 public:
  // Creates an OpenGL core-profile context of at least major.minor and makes
  // it current on this thread. Throws GlContextError saying which step failed
  // and what usually fixes it.
  explicit HeadlessGlContext(int major = 4, int minor = 5);
  ~HeadlessGlContext();
  HeadlessGlContext(const HeadlessGlContext&) = delete;
  HeadlessGlContext& operator=(const HeadlessGlContext&) = delete;

  const GlContextInfo& info() const { return info_; }
  // Makes the context current on the calling thread.
  void makeCurrent();

 private:
  struct Egl;
  std::unique_ptr<Egl> egl_;
  GlContextInfo info_;
};

}  // namespace nadir::render
