#pragma once
// OpenGL 4.5 core declarations for render/'s .cpp files (never for headers).
// GLVND's libOpenGL exports the core entry points, so no loader is needed.

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/gl.h>
#include <GL/glext.h>

#include <string>

#include <opencv2/core/mat.hpp>

namespace nadir::render {

// Compiles and links a vertex + fragment program; throws GlContextError with
// the driver's log on failure.
GLuint linkProgram(const std::string& name, const std::string& vertex_source,
                   const std::string& fragment_source);

// Uploads an 8-bit RGB image (CV_8UC3) as an RGBA8 texture with mipmaps,
// clamped at its edges; returns the texture name (bound to GL_TEXTURE_2D).
GLuint uploadRgbTexture(const cv::Mat& rgb, GLenum min_filter);

// Throws GlContextError naming what if glGetError reports an error.
void checkGl(const char* what);

}  // namespace nadir::render
