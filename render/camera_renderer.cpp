#include "render/camera_renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "render/egl_context.h"
#include "render/gl.h"

namespace nadir::render {
namespace {

constexpr const char* kPostVertex = R"(#version 450 core
void main() {
  // One triangle covering the viewport.
  vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
)";

// Distortion by lookup, then exposure noise: shot noise (variance proportional
// to the signal) and read noise, from a hash of pixel, frame and seed.
constexpr const char* kPostFragment = R"(#version 450 core
uniform sampler2D u_scene;
uniform sampler2D u_map;
uniform bool u_distort;
uniform bool u_gray;
uniform float u_read_noise;
uniform float u_electrons_per_count;
uniform uvec2 u_seed;
out vec4 out_colour;

uint mix32(uint h) {
  h ^= h >> 16; h *= 0x7feb352du; h ^= h >> 15; h *= 0x846ca68bu; h ^= h >> 16;
  return h;
}
float uniform01(uvec2 pixel, uint stream) {
  uint h = mix32(pixel.x * 0x8da6b343u ^ pixel.y * 0xd8163841u ^ u_seed.x ^ mix32(u_seed.y + stream));
  return (float(h >> 8) + 0.5) / 16777216.0;
}
float gaussian(uvec2 pixel, uint channel) {
  float u1 = uniform01(pixel, 2u * channel);
  float u2 = uniform01(pixel, 2u * channel + 1u);
  return sqrt(-2.0 * log(u1)) * cos(6.28318530718 * u2);
}
float expose(float value01, uvec2 pixel, uint channel) {
  float counts = value01 * 255.0;
  float variance = u_read_noise * u_read_noise;
  if (u_electrons_per_count > 0.0) variance += counts / u_electrons_per_count;
  counts += sqrt(variance) * gaussian(pixel, channel);
  return clamp(floor(counts + 0.5), 0.0, 255.0) / 255.0;
}
void main() {
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  vec4 colour;
  if (u_distort) {
    vec2 scene_uv = texelFetch(u_map, pixel, 0).rg;
    colour = scene_uv.x < 0.0 ? vec4(0.5) : texture(u_scene, scene_uv);
  } else {
    colour = texelFetch(u_scene, pixel, 0);
  }
  uvec2 p = uvec2(pixel);
  if (u_gray) {
    out_colour = vec4(expose(colour.r, p, 0u), 0.0, 0.0, 1.0);
  } else {
    out_colour = vec4(expose(colour.r, p, 0u), expose(colour.g, p, 1u), expose(colour.b, p, 2u), 1.0);
  }
}
)";

}  // namespace

struct CameraRenderer::Target {
  GLuint framebuffer = 0;
  GLuint colour = 0;
  GLuint depth = 0;
  int width = 0;
  int height = 0;

  Target(int w, int h, bool gray, bool with_depth) : width(w), height(h) {
    glGenFramebuffers(1, &framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    glGenTextures(1, &colour);
    glBindTexture(GL_TEXTURE_2D, colour);
    glTexStorage2D(GL_TEXTURE_2D, 1, gray ? GL_R8 : GL_RGBA8, w, h);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, colour, 0);
    if (with_depth) {
      glGenTextures(1, &depth);
      glBindTexture(GL_TEXTURE_2D, depth);
      glTexStorage2D(GL_TEXTURE_2D, 1, GL_DEPTH_COMPONENT32F, w, h);
      glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, depth, 0);
    }
    const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
      throw GlContextError("offscreen framebuffer " + std::to_string(w) + "x" + std::to_string(h) +
                           " is incomplete (status 0x" + std::to_string(status) + ")");
    }
  }
  ~Target() {
    glDeleteTextures(1, &colour);
    glDeleteTextures(1, &depth);
    glDeleteFramebuffers(1, &framebuffer);
  }
};

CameraRenderer::CameraRenderer(TerrainRenderer& terrain, const CameraParams& params)
    : terrain_(terrain), params_(params), intrinsics_(params.intrinsics()) {
  core::validateParams([this](core::ParamVisitor& v) { params_.visit(v); }, "camera parameters");
  createTargets();
}

CameraRenderer::~CameraRenderer() {
  scene_.reset();
  output_.reset();
  glDeleteTextures(1, &distortion_map_);
  glDeleteVertexArrays(1, &post_vertex_array_);
  glDeleteProgram(post_program_);
}

void CameraRenderer::createTargets() {
  const bool gray = params_.pixel_format == "gray8";
  const bool noise =
      params_.read_noise_counts > 0.0 || params_.shot_noise_electrons_per_count > 0.0;
  const bool distort = intrinsics_.hasDistortion();
  post_pass_ = noise || distort;
  scene_intrinsics_ = intrinsics_;
  scene_intrinsics_.distortion = {};
  if (distort) {
    // Undistorted footprint of the distorted image's border, one pixel of margin.
    double min_x = 1e9, max_x = -1e9, min_y = 1e9, max_y = -1e9;
    const auto include = [&](double u, double v) {
      const auto xy = intrinsics_.undistortPixel({u, v});
      if (!xy) {
        throw GlContextError("camera distortion does not invert at pixel (" + std::to_string(u) +
                             ", " + std::to_string(v) + "): coefficients out of a lens's range");
      }
      min_x = std::min(min_x, xy->x());
      max_x = std::max(max_x, xy->x());
      min_y = std::min(min_y, xy->y());
      max_y = std::max(max_y, xy->y());
    };
    for (int u = 0; u < intrinsics_.width; ++u) {
      include(u - 0.5, -0.5);
      include(u - 0.5, intrinsics_.height - 0.5);
    }
    for (int v = 0; v < intrinsics_.height; ++v) {
      include(-0.5, v - 0.5);
      include(intrinsics_.width - 0.5, v - 0.5);
    }
    scene_intrinsics_.width = static_cast<int>(std::ceil((max_x - min_x) * intrinsics_.fx)) + 4;
    scene_intrinsics_.height = static_cast<int>(std::ceil((max_y - min_y) * intrinsics_.fy)) + 4;
    if (scene_intrinsics_.width > 4 * intrinsics_.width ||
        scene_intrinsics_.height > 4 * intrinsics_.height) {
      throw GlContextError(
          "camera distortion widens the view more than 4 times: check the coefficients");
    }
    scene_intrinsics_.cx = -min_x * intrinsics_.fx + 1.5;
    scene_intrinsics_.cy = -min_y * intrinsics_.fy + 1.5;

    // For each output pixel, where it looks in the undistorted scene.
    map_x_.create(intrinsics_.height, intrinsics_.width, CV_32FC1);
    map_y_.create(intrinsics_.height, intrinsics_.width, CV_32FC1);
    cv::Mat uv(intrinsics_.height, intrinsics_.width, CV_32FC2);
    for (int v = 0; v < intrinsics_.height; ++v) {
      for (int u = 0; u < intrinsics_.width; ++u) {
        const auto xy =
            intrinsics_.undistortPixel({static_cast<double>(u), static_cast<double>(v)});
        const double us = xy ? scene_intrinsics_.fx * xy->x() + scene_intrinsics_.cx : -1e6;
        const double vs = xy ? scene_intrinsics_.fy * xy->y() + scene_intrinsics_.cy : -1e6;
        map_x_.at<float>(v, u) = static_cast<float>(us);
        map_y_.at<float>(v, u) = static_cast<float>(vs);
        uv.at<cv::Vec2f>(v, u) =
            xy ? cv::Vec2f(static_cast<float>((us + 0.5) / scene_intrinsics_.width),
                           static_cast<float>((vs + 0.5) / scene_intrinsics_.height))
               : cv::Vec2f(-1.0f, -1.0f);
      }
    }
    glGenTextures(1, &distortion_map_);
    glBindTexture(GL_TEXTURE_2D, distortion_map_);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RG32F, intrinsics_.width, intrinsics_.height);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, intrinsics_.width, intrinsics_.height, GL_RG, GL_FLOAT,
                    uv.data);
  }
  scene_ = std::make_unique<Target>(scene_intrinsics_.width, scene_intrinsics_.height, gray, true);
  if (post_pass_) {
    output_ = std::make_unique<Target>(intrinsics_.width, intrinsics_.height, gray, false);
    post_program_ = linkProgram("camera post-processing", kPostVertex, kPostFragment);
    glGenVertexArrays(1, &post_vertex_array_);
  }
  checkGl("creating the camera's framebuffers");
}

RenderedImage CameraRenderer::render(const Eigen::Isometry3d& T_world_cam, std::int64_t utime,
                                     bool with_depth) {
  const bool gray = params_.pixel_format == "gray8";
  RenderedImage out;
  out.utime = utime;
  out.T_world_cam = T_world_cam;

  DrawView view;
  view.T_world_cam = T_world_cam;
  view.intrinsics = scene_intrinsics_;
  view.near_m = params_.near_m;
  view.far_m = params_.far_m;
  view.gain = params_.gain;
  view.ground_detail = params_.ground_detail;
  view.gray = gray;
  glBindFramebuffer(GL_FRAMEBUFFER, scene_->framebuffer);
  glViewport(0, 0, scene_->width, scene_->height);
  out.stats = terrain_.draw(view);

  cv::Mat scene_depth;
  if (with_depth) {
    scene_depth.create(scene_->height, scene_->width, CV_32FC1);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, scene_->width, scene_->height, GL_DEPTH_COMPONENT, GL_FLOAT,
                 scene_depth.data);
    const double n = params_.near_m, f = params_.far_m;
    scene_depth.forEach<float>([n, f](float& d, const int*) {
      d = d >= 1.0f ? std::numeric_limits<float>::infinity()
                    : static_cast<float>(2.0 * f * n / ((f + n) - (2.0 * d - 1.0) * (f - n)));
    });
  }

  Target* result = scene_.get();
  if (post_pass_) {
    glBindFramebuffer(GL_FRAMEBUFFER, output_->framebuffer);
    glViewport(0, 0, output_->width, output_->height);
    glDisable(GL_DEPTH_TEST);
    glUseProgram(post_program_);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, scene_->colour);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, distortion_map_);
    glActiveTexture(GL_TEXTURE0);
    glUniform1i(glGetUniformLocation(post_program_, "u_scene"), 0);
    glUniform1i(glGetUniformLocation(post_program_, "u_map"), 1);
    glUniform1i(glGetUniformLocation(post_program_, "u_distort"),
                intrinsics_.hasDistortion() ? 1 : 0);
    glUniform1i(glGetUniformLocation(post_program_, "u_gray"), gray ? 1 : 0);
    glUniform1f(glGetUniformLocation(post_program_, "u_read_noise"),
                static_cast<float>(params_.read_noise_counts));
    glUniform1f(glGetUniformLocation(post_program_, "u_electrons_per_count"),
                static_cast<float>(params_.shot_noise_electrons_per_count));
    const auto seed = static_cast<std::uint64_t>(params_.noise_seed);
    const auto frame = static_cast<std::uint64_t>(utime);
    glUniform2ui(glGetUniformLocation(post_program_, "u_seed"),
                 static_cast<GLuint>(seed ^ (seed >> 32) ^ frame),
                 static_cast<GLuint>((frame >> 32) ^ (frame * 0x9E3779B9u)));
    glBindVertexArray(post_vertex_array_);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    result = output_.get();
  }

  out.image.create(intrinsics_.height, intrinsics_.width, gray ? CV_8UC1 : CV_8UC3);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, result->framebuffer);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, intrinsics_.width, intrinsics_.height, gray ? GL_RED : GL_RGB,
               GL_UNSIGNED_BYTE, out.image.data);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  checkGl("rendering a camera image");

  if (with_depth) {
    if (intrinsics_.hasDistortion()) {
      cv::remap(scene_depth, out.depth_m, map_x_, map_y_, cv::INTER_NEAREST, cv::BORDER_CONSTANT,
                cv::Scalar(std::numeric_limits<float>::infinity()));
    } else {
      out.depth_m = scene_depth;
    }
  }
  return out;
}

}  // namespace nadir::render
