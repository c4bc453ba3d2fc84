#include "render/gl.h"

#include <vector>

#include "render/egl_context.h"

namespace nadir::render {
namespace {

GLuint compile(const std::string& name, GLenum stage, const std::string& source) {
  const GLuint shader = glCreateShader(stage);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint length = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
    std::vector<char> log(static_cast<std::size_t>(std::max(length, 1)));
    glGetShaderInfoLog(shader, length, nullptr, log.data());
    glDeleteShader(shader);
    throw GlContextError("shader " + name +
                         (stage == GL_VERTEX_SHADER ? " (vertex)" : " (fragment)") +
                         " does not compile: " + log.data());
  }
  return shader;
}

}  // namespace

GLuint linkProgram(const std::string& name, const std::string& vertex_source,
                   const std::string& fragment_source) {
  const GLuint vertex = compile(name, GL_VERTEX_SHADER, vertex_source);
  const GLuint fragment = compile(name, GL_FRAGMENT_SHADER, fragment_source);
  const GLuint program = glCreateProgram();
  glAttachShader(program, vertex);
  glAttachShader(program, fragment);
  glLinkProgram(program);
  glDeleteShader(vertex);
  glDeleteShader(fragment);
  GLint ok = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint length = 0;
    glGetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
    std::vector<char> log(static_cast<std::size_t>(std::max(length, 1)));
    glGetProgramInfoLog(program, length, nullptr, log.data());
    glDeleteProgram(program);
    throw GlContextError("shader program " + name + " does not link: " + log.data());
  }
  return program;
}

GLuint uploadRgbTexture(const cv::Mat& rgb, GLenum min_filter) {
  GLuint texture = 0;
  glGenTextures(1, &texture);
  glBindTexture(GL_TEXTURE_2D, texture);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, rgb.cols, rgb.rows, 0, GL_RGB, GL_UNSIGNED_BYTE,
               rgb.data);
  glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, static_cast<GLint>(min_filter));
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return texture;
}

void checkGl(const char* what) {
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR) {
    throw GlContextError(std::string("OpenGL error 0x") + std::to_string(error) + " in " + what);
  }
}

}  // namespace nadir::render
