// Headless OpenGL through EGL's surfaceless Mesa platform: what CI renders with.

#define GL_GLEXT_PROTOTYPES
#include <GL/gl.h>
#include <GL/glext.h>

#include <thread>

#include <gtest/gtest.h>

#include "render/egl_context.h"

namespace nadir::render {
namespace {

// A 4.5 core context is created without any display and reports itself.
TEST(HeadlessGl, CreatesCoreContext45) {
  HeadlessGlContext context(4, 5);
  const GlContextInfo& info = context.info();
  EXPECT_TRUE(info.core_profile);
  EXPECT_GE(info.gl_major * 10 + info.gl_minor, 45) << info.gl_version;
  EXPECT_FALSE(info.gl_renderer.empty());
  EXPECT_NE(info.egl_version.find("1."), std::string::npos) << info.egl_version;
}

// The context really executes GL commands: clearing a renderbuffer to a colour reads back that
// colour.
TEST(HeadlessGl, ClearsAndReadsBackAPixel) {
  HeadlessGlContext context;
  GLuint framebuffer = 0, colour = 0;
  glGenFramebuffers(1, &framebuffer);
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  glGenRenderbuffers(1, &colour);
  glBindRenderbuffer(GL_RENDERBUFFER, colour);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, 4, 4);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour);
  ASSERT_EQ(glCheckFramebufferStatus(GL_FRAMEBUFFER), static_cast<GLenum>(GL_FRAMEBUFFER_COMPLETE));
  glViewport(0, 0, 4, 4);
  glClearColor(1.0f, 0.5f, 0.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  unsigned char pixel[4] = {0, 0, 0, 0};
  glReadPixels(2, 2, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, pixel);
  EXPECT_EQ(pixel[0], 255);
  EXPECT_NEAR(pixel[1], 128, 1);  // 0.5 rounds to 127 or 128
  EXPECT_EQ(pixel[2], 0);
  EXPECT_EQ(pixel[3], 255);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  glDeleteRenderbuffers(1, &colour);
  glDeleteFramebuffers(1, &framebuffer);
}

// Two contexts can live at once, each current on its own thread.
TEST(HeadlessGl, ContextPerThread) {
  HeadlessGlContext first;
  std::string other_renderer;
  std::thread worker([&] {
    HeadlessGlContext second;
    other_renderer = second.info().gl_renderer;
  });
  worker.join();
  EXPECT_EQ(other_renderer, first.info().gl_renderer);
}

}  // namespace
}  // namespace nadir::render
