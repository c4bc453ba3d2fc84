#include "render/camera_renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/stage_times.h"
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

// Exposure noise: shot noise (variance proportional to the signal) and read
// noise, from a hash of pixel, frame and seed. Shared by both post passes.
constexpr const char* kNoise = R"(
uniform float u_read_noise;
uniform float u_electrons_per_count;
uniform uvec2 u_seed;
uniform bool u_gray;
uniform float u_exposure_gain;
uniform float u_vignetting_k;
uniform vec4 u_output_k;
uniform float u_response_gamma;
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
  if (variance > 0.0) counts += sqrt(variance) * gaussian(pixel, channel);
  if (u_response_gamma != 1.0)
    counts = 255.0 * pow(clamp(counts, 0.0, 255.0) / 255.0, 1.0 / u_response_gamma);
  return clamp(floor(counts + 0.5), 0.0, 255.0) / 255.0;
}
void writeExposed(vec4 colour) {
  uvec2 p = uvec2(ivec2(gl_FragCoord.xy));
  if (u_vignetting_k > 0.0 || u_exposure_gain != 1.0) {
    vec2 xy = (gl_FragCoord.xy - 0.5 - u_output_k.zw) / u_output_k.xy;
    float v = 1.0 + u_vignetting_k * dot(xy, xy);
    colour *= u_exposure_gain / (v * v);
  }
  if (u_gray) {
    out_colour = vec4(expose(colour.r, p, 0u), 0.0, 0.0, 1.0);
  } else {
    out_colour = vec4(expose(colour.r, p, 0u), expose(colour.g, p, 1u), expose(colour.b, p, 2u), 1.0);
  }
}
)";

// A still camera: distortion by lookup, then the noise.
constexpr const char* kPostFragment = R"(
uniform sampler2D u_scene;
uniform sampler2D u_map;
uniform bool u_distort;
void main() {
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  vec4 colour;
  if (u_distort) {
    vec2 scene_uv = texelFetch(u_map, pixel, 0).rg;
    colour = scene_uv.x < 0.0 ? vec4(0.5) : texture(u_scene, scene_uv);
  } else {
    colour = texelFetch(u_scene, pixel, 0);
  }
  writeExposed(colour);
}
)";

// A moving camera (rolling shutter, motion blur): a mesh over the output
// image, a vertex every kMotionGridPx pixels. At each vertex, the ray through
// it at its row's time meets the ground of the frame time's depth (two Newton
// steps), and that ground point is seen at the exposure's two ends; the
// fragments between interpolate those two positions (the warp of a height
// field is smooth) and average the scene along the line between them.
constexpr const char* kMotionVertex = R"(#version 450 core
uniform sampler2D u_depth;
uniform sampler2D u_map;
uniform bool u_distort;
uniform vec3 u_omega;
uniform vec3 u_velocity;
uniform float u_readout_s;
uniform float u_exposure_s;
uniform vec4 u_scene_k;
uniform vec4 u_output_k;
uniform vec2 u_scene_size;
uniform vec2 u_output_size;
uniform vec2 u_depth_range;
uniform int u_grid_px;
uniform int u_cells_x;
noperspective out vec2 v_p0;
noperspective out vec2 v_p1;
out float v_inside;

// exp([w]x) to third order: within 1e-4 rad of it up to 0.3 rad, far more
// than a frame's exposure or readout turns.
mat3 rotationOf(vec3 w) {
  mat3 K = mat3(0.0, w.z, -w.y, -w.z, 0.0, w.x, w.y, -w.x, 0.0);
  mat3 K2 = K * K;
  return mat3(1.0) + K + 0.5 * K2 + (1.0 / 6.0) * (K2 * K);
}
vec2 projectScene(vec3 X) {
  return vec2(u_scene_k.x * X.x / X.z + u_scene_k.z, u_scene_k.y * X.y / X.z + u_scene_k.w);
}
float sceneDepth(vec2 px) {
  ivec2 p = clamp(ivec2(floor(px + 0.5)), ivec2(0), ivec2(u_scene_size) - 1);
  float d = texelFetch(u_depth, p, 0).r;
  float n = u_depth_range.x, f = u_depth_range.y;
  return 2.0 * f * n / ((f + n) - (2.0 * d - 1.0) * (f - n));
}
void main() {
  // Indexed: vertex i of the (cells_x + 1) x (cells_y + 1) grid.
  ivec2 c = ivec2(gl_VertexID % (u_cells_x + 1), gl_VertexID / (u_cells_x + 1));
  vec2 window = min(vec2(c * u_grid_px), u_output_size);
  gl_Position = vec4(window / u_output_size * 2.0 - 1.0, 0.0, 1.0);
  vec2 pixel = window - 0.5;
  vec2 xy;
  v_inside = 1.0;
  if (u_distort) {
    vec2 scene_uv = texture(u_map, window / u_output_size).rg;
    v_inside = scene_uv.x < 0.0 ? 0.0 : 1.0;
    xy = (scene_uv * u_scene_size - 0.5 - u_scene_k.zw) / u_scene_k.xy;
  } else {
    xy = (pixel - u_output_k.zw) / u_output_k.xy;
  }
  float t_row = (pixel.y / max(u_output_size.y - 1.0, 1.0) - 0.5) * u_readout_s;
  vec3 r = vec3(xy, 1.0);
  mat3 R = rotationOf(u_omega * t_row);
  vec3 o = u_velocity * t_row;
  vec3 d = R * r;
  float s = sceneDepth(projectScene(d)) / d.z;
  for (int i = 0; i < 2; ++i) {
    vec3 X = o + s * d;
    s += (sceneDepth(projectScene(X)) - X.z) / d.z;
  }
  vec3 P = s * r;
  float t0 = t_row - 0.5 * u_exposure_s, t1 = t_row + 0.5 * u_exposure_s;
  v_p0 = projectScene(u_velocity * t0 + rotationOf(u_omega * t0) * P);
  v_p1 = projectScene(u_velocity * t1 + rotationOf(u_omega * t1) * P);
}
)";

constexpr const char* kMotionFragment = R"(
uniform sampler2D u_scene;
uniform vec2 u_scene_size;
uniform int u_blur_samples;
noperspective in vec2 v_p0;
noperspective in vec2 v_p1;
in float v_inside;
void main() {
  vec4 colour = vec4(0.5);
  if (v_inside > 0.5) {
    // Instants half a pixel apart along the smear at most (bilinear lookups
    // fill in between), up to u_blur_samples.
    int samples = clamp(int(ceil(2.0 * length(v_p1 - v_p0))), 1, u_blur_samples);
    colour = vec4(0.0);
    for (int k = 0; k < samples; ++k) {
      vec2 p = mix(v_p0, v_p1, (float(k) + 0.5) / float(samples));
      colour += texture(u_scene, (p + 0.5) / u_scene_size);
    }
    colour /= float(samples);
  }
  writeExposed(colour);
}
)";

constexpr int kMotionGridPx = 32;

std::string fragmentSource(const char* body) {
  return std::string("#version 450 core\n") + kNoise + body;
}

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
  glDeleteProgram(motion_program_);
  glDeleteBuffers(1, &motion_indices_);
}

void CameraRenderer::createTargets() {
  const bool gray = params_.pixel_format == "gray8";
  const bool noise =
      params_.read_noise_counts > 0.0 || params_.shot_noise_electrons_per_count > 0.0;
  const bool distort = intrinsics_.hasDistortion();
  post_pass_ = noise || distort || params_.modelsMotion() || params_.vignetting ||
               params_.response_curve || params_.auto_exposure;
  scene_intrinsics_ = intrinsics_;
  scene_intrinsics_.distortion = {};
  // With motion, room for what moves into the frame during the exposure or readout.
  const int margin = params_.modelsMotion() ? params_.motion_margin_px : 0;
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
    scene_intrinsics_.width += 2 * margin;
    scene_intrinsics_.height += 2 * margin;
    scene_intrinsics_.cx = -min_x * intrinsics_.fx + 1.5 + margin;
    scene_intrinsics_.cy = -min_y * intrinsics_.fy + 1.5 + margin;

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
  } else {
    scene_intrinsics_.width += 2 * margin;
    scene_intrinsics_.height += 2 * margin;
    scene_intrinsics_.cx += margin;
    scene_intrinsics_.cy += margin;
  }
  scene_ = std::make_unique<Target>(scene_intrinsics_.width, scene_intrinsics_.height, gray, true);
  if (post_pass_) {
    output_ = std::make_unique<Target>(intrinsics_.width, intrinsics_.height, gray, false);
    glGenVertexArrays(1, &post_vertex_array_);
    post_program_ =
        linkProgram("camera post-processing", kPostVertex, fragmentSource(kPostFragment));
    if (params_.modelsMotion()) {
      motion_program_ = linkProgram("camera motion (rolling shutter, blur)", kMotionVertex,
                                    fragmentSource(kMotionFragment));
      // Two triangles per cell of the grid, the vertices shared.
      motion_cells_x_ = (intrinsics_.width + kMotionGridPx - 1) / kMotionGridPx;
      const int cells_y = (intrinsics_.height + kMotionGridPx - 1) / kMotionGridPx;
      std::vector<GLuint> indices;
      indices.reserve(static_cast<std::size_t>(6 * motion_cells_x_ * cells_y));
      const auto vertex = [this](int x, int y) {
        return static_cast<GLuint>(y * (motion_cells_x_ + 1) + x);
      };
      for (int y = 0; y < cells_y; ++y) {
        for (int x = 0; x < motion_cells_x_; ++x) {
          for (const GLuint i : {vertex(x, y), vertex(x + 1, y), vertex(x + 1, y + 1), vertex(x, y),
                                 vertex(x + 1, y + 1), vertex(x, y + 1)})
            indices.push_back(i);
        }
      }
      motion_index_count_ = static_cast<int>(indices.size());
      glBindVertexArray(post_vertex_array_);
      glGenBuffers(1, &motion_indices_);
      glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, motion_indices_);
      glBufferData(GL_ELEMENT_ARRAY_BUFFER,
                   static_cast<GLsizeiptr>(indices.size() * sizeof(GLuint)), indices.data(),
                   GL_STATIC_DRAW);
      glBindVertexArray(0);
    }
  }
  checkGl("creating the camera's framebuffers");
}

double CameraRenderer::vignettingK() const {
  return params_.vignetting ? render::vignettingK(params_.vignetting_corner, intrinsics_) : 0.0;
}

double CameraRenderer::exposureGain(std::int64_t utime) {
  if (!params_.auto_exposure) return 1.0;
  if (ae_last_utime_ >= 0 && utime > ae_last_utime_) {
    // log g moves towards log(target / mean) by 1 - e^(-dt / tau) a frame.
    const double dt_s = static_cast<double>(utime - ae_last_utime_) * 1e-6;
    const double step = 1.0 - std::exp(-dt_s / params_.ae_time_constant_s);
    const double error = std::log(params_.ae_target_counts / std::max(ae_last_mean_counts_, 0.5));
    ae_gain_ =
        std::clamp(ae_gain_ * std::exp(step * error), params_.ae_gain_min, params_.ae_gain_max);
  }
  return ae_gain_;
}

void CameraRenderer::expectNextViews(const DrawView& view, std::int64_t utime) {
  const Eigen::Vector3d p_m = view.T_world_cam.translation();
  const double dt_s = static_cast<double>(utime - last_utime_) * 1e-6;
  // The camera flies on at its last velocity and attitude; a guess only
  // decides which tiles are made ahead, never what is drawn.
  if (last_utime_ >= 0 && dt_s > 0.0 && dt_s < 1.0) {
    const Eigen::Vector3d v_mps = (p_m - last_p_world_cam_m_) / dt_s;
    std::vector<DrawView> next;
    for (const double ahead_s : {0.5, 1.0, 2.0}) {
      next.push_back(view);
      next.back().T_world_cam.translation() = p_m + ahead_s * v_mps;
    }
    terrain_.expect(next);
  }
  last_p_world_cam_m_ = p_m;
  last_utime_ = utime;
}

RenderedImage CameraRenderer::render(const Eigen::Isometry3d& T_world_cam, std::int64_t utime,
                                     bool with_depth, const CameraMotion& motion) {
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
  {
    const core::ScopedStage stage("draw");
    out.stats = terrain_.draw(view);
  }
  expectNextViews(view, utime);
  if (core::stageTimesEnabled()) {
    // llvmpipe rasterises when the pixels are needed: timed, that is a stage of its own.
    const core::ScopedStage stage("rasterise");
    glFinish();
  }

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
    const core::ScopedStage stage("post-process");
    const bool moving = params_.modelsMotion();
    const GLuint program = moving ? motion_program_ : post_program_;
    const auto at = [program](const char* name) { return glGetUniformLocation(program, name); };
    glBindFramebuffer(GL_FRAMEBUFFER, output_->framebuffer);
    glViewport(0, 0, output_->width, output_->height);
    glDisable(GL_DEPTH_TEST);
    glUseProgram(program);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, scene_->colour);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, distortion_map_);
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_2D, scene_->depth);
    glActiveTexture(GL_TEXTURE0);
    glUniform1i(at("u_scene"), 0);
    glUniform1i(at("u_map"), 1);
    glUniform1i(at("u_depth"), 2);
    glUniform1i(at("u_distort"), intrinsics_.hasDistortion() ? 1 : 0);
    glUniform1i(at("u_gray"), gray ? 1 : 0);
    glUniform1f(at("u_read_noise"), static_cast<float>(params_.read_noise_counts));
    glUniform1f(at("u_electrons_per_count"),
                static_cast<float>(params_.shot_noise_electrons_per_count));
    const auto seed = static_cast<std::uint64_t>(params_.noise_seed);
    const auto frame = static_cast<std::uint64_t>(utime);
    glUniform2ui(at("u_seed"), static_cast<GLuint>(seed ^ (seed >> 32) ^ frame),
                 static_cast<GLuint>((frame >> 32) ^ (frame * 0x9E3779B9u)));
    glUniform1f(at("u_exposure_gain"), static_cast<float>(exposureGain(utime)));
    glUniform1f(at("u_vignetting_k"), static_cast<float>(vignettingK()));
    glUniform4f(at("u_output_k"), static_cast<float>(intrinsics_.fx),
                static_cast<float>(intrinsics_.fy), static_cast<float>(intrinsics_.cx),
                static_cast<float>(intrinsics_.cy));
    glUniform1f(at("u_response_gamma"),
                params_.response_curve ? static_cast<float>(params_.response_gamma) : 1.f);
    glBindVertexArray(post_vertex_array_);
    if (moving) {
      const Eigen::Vector3f omega = motion.omega_cam_rps.cast<float>();
      const Eigen::Vector3f velocity = motion.v_cam_mps.cast<float>();
      glUniform3f(at("u_omega"), omega.x(), omega.y(), omega.z());
      glUniform3f(at("u_velocity"), velocity.x(), velocity.y(), velocity.z());
      glUniform1f(at("u_readout_s"),
                  params_.rolling_shutter ? static_cast<float>(params_.readout_s) : 0.f);
      glUniform1f(at("u_exposure_s"),
                  params_.motion_blur ? static_cast<float>(params_.exposure_s) : 0.f);
      glUniform1i(at("u_blur_samples"), params_.motion_blur ? params_.motion_blur_samples : 1);
      glUniform4f(at("u_scene_k"), static_cast<float>(scene_intrinsics_.fx),
                  static_cast<float>(scene_intrinsics_.fy),
                  static_cast<float>(scene_intrinsics_.cx),
                  static_cast<float>(scene_intrinsics_.cy));
      glUniform2f(at("u_scene_size"), static_cast<float>(scene_->width),
                  static_cast<float>(scene_->height));
      glUniform2f(at("u_output_size"), static_cast<float>(output_->width),
                  static_cast<float>(output_->height));
      glUniform2f(at("u_depth_range"), static_cast<float>(params_.near_m),
                  static_cast<float>(params_.far_m));
      glUniform1i(at("u_grid_px"), kMotionGridPx);
      glUniform1i(at("u_cells_x"), motion_cells_x_);
      glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, motion_indices_);
      glDrawElements(GL_TRIANGLES, motion_index_count_, GL_UNSIGNED_INT, nullptr);
    } else {
      glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    glBindVertexArray(0);
    result = output_.get();
  }

  {
    const core::ScopedStage stage("readback");
    out.image.create(intrinsics_.height, intrinsics_.width, gray ? CV_8UC1 : CV_8UC3);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, result->framebuffer);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, intrinsics_.width, intrinsics_.height, gray ? GL_RED : GL_RGB,
                 GL_UNSIGNED_BYTE, out.image.data);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }
  checkGl("rendering a camera image");
  if (params_.auto_exposure) {
    const cv::Scalar mean = cv::mean(out.image);
    ae_last_mean_counts_ = gray ? mean[0] : (mean[0] + mean[1] + mean[2]) / 3.0;
    ae_last_utime_ = utime;
  }

  if (with_depth) {
    if (intrinsics_.hasDistortion()) {
      cv::remap(scene_depth, out.depth_m, map_x_, map_y_, cv::INTER_NEAREST, cv::BORDER_CONSTANT,
                cv::Scalar(std::numeric_limits<float>::infinity()));
    } else if (params_.modelsMotion()) {
      const int m = params_.motion_margin_px;
      out.depth_m = scene_depth(cv::Rect(m, m, intrinsics_.width, intrinsics_.height)).clone();
    } else {
      out.depth_m = scene_depth;
    }
  }
  return out;
}

}  // namespace nadir::render
