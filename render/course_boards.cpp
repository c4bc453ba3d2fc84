#include "render/course_boards.h"

#include <array>
#include <cmath>
#include <map>
#include <string>
#include <tuple>

#include <opencv2/imgproc.hpp>

#include "render/gl.h"

namespace nadir::render {
namespace {

constexpr const char* kVertexShader = R"(#version 450 core
layout(location = 0) in vec3 local_ned;
layout(location = 1) in vec2 uv;
layout(location = 2) in float flat_grey;
uniform mat4 u_clip_from_local;
out vec2 v_uv;
out float v_flat;
void main() {
  gl_Position = u_clip_from_local * vec4(local_ned, 1.0);
  v_uv = uv;
  v_flat = flat_grey;
}
)";

// A negative flat grey takes the pattern texture instead.
constexpr const char* kFragmentShader = R"(#version 450 core
in vec2 v_uv;
in float v_flat;
uniform sampler2D u_texture;
uniform float u_gain;
uniform bool u_gray;
out vec4 out_colour;
void main() {
  vec3 colour = (v_flat < 0.0 ? texture(u_texture, v_uv).rgb : vec3(v_flat / 255.0)) * u_gain;
  out_colour = u_gray ? vec4(dot(colour, vec3(0.299, 0.587, 0.114)), 0.0, 0.0, 1.0) : vec4(colour, 1.0);
}
)";

// Pattern texture side, px: a 0.45 m board's texel is 0.9 mm, finer than a
// 256 px camera of 50 deg resolves from 0.3 m.
constexpr int kPatternPx = 512;
// Greys of what is not the pattern, 8-bit counts: the board's back and the
// posts' faces (lit from above and the side).
constexpr float kBackGrey = 200.0f;
constexpr std::array<float, 3> kPostGrey = {70.0f, 55.0f, 85.0f};  // sides, other sides, top

struct Mesh {
  std::vector<float> data;  // x y z u v grey per vertex
  void vertex(const Eigen::Vector3d& p, double u, double v, float grey) {
    data.insert(data.end(),
                {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()),
                 static_cast<float>(u), static_cast<float>(v), grey});
  }
  // Two triangles a b c, a c d.
  void quad(const std::array<Eigen::Vector3d, 4>& p, const std::array<std::array<double, 2>, 4>& uv,
            float grey) {
    for (const int i : {0, 1, 2, 0, 2, 3}) vertex(p[i], uv[i][0], uv[i][1], grey);
  }
};

}  // namespace

struct CourseBoardRenderer::GpuBoard {
  Eigen::Vector3d origin_ned;
  GLuint vertex_array = 0;
  GLuint vertex_buffer = 0;
  GLuint texture = 0;
  int vertices = 0;
  ~GpuBoard() {
    glDeleteTextures(1, &texture);
    glDeleteBuffers(1, &vertex_buffer);
    glDeleteVertexArrays(1, &vertex_array);
  }
};

CourseBoardRenderer::CourseBoardRenderer() {
  program_ = linkProgram("course board", kVertexShader, kFragmentShader);
}

CourseBoardRenderer::~CourseBoardRenderer() {
  boards_.clear();
  glDeleteProgram(program_);
}

void CourseBoardRenderer::setBoards(const std::vector<terrain::CourseBoard>& boards,
                                    const terrain::World& world) {
  boards_.clear();
  // Boards of one pattern (the gates) share its drawing.
  std::map<std::tuple<std::string, std::string, std::int64_t>, cv::Mat> patterns;
  for (const terrain::CourseBoard& board : boards) {
    auto gpu = std::make_unique<GpuBoard>();
    const double floor_up_m = world.groundUp_m(board.north_m, board.east_m);
    gpu->origin_ned = Eigen::Vector3d(board.north_m, board.east_m, -floor_up_m);
    Mesh mesh;
    const terrain::BoardFrame frame = terrain::boardFrame(board, floor_up_m);
    const auto corner = [&](double x, double y) -> Eigen::Vector3d {
      Eigen::Vector3d local = terrain::boardPoint(frame, board.board_m, x, y);
      local -= gpu->origin_ned;
      return local;
    };
    const std::array<Eigen::Vector3d, 4> face = {corner(0, 0), corner(1, 0), corner(1, 1),
                                                 corner(0, 1)};
    mesh.quad(face, {{{0, 0}, {1, 0}, {1, 1}, {0, 1}}}, -1.0f);
    // The back, a hair behind the face.
    const Eigen::Vector3d behind = 0.001 * frame.forward_ned;
    std::array<Eigen::Vector3d, 4> back;
    for (const int i : {0, 1, 2, 3})
      back[static_cast<std::size_t>(i)] = face[static_cast<std::size_t>((5 - i) % 4)] + behind;
    mesh.quad(back, {{{0, 0}, {0, 0}, {0, 0}, {0, 0}}}, kBackGrey);
    for (const terrain::Post& post : terrain::boardPosts(board)) {
      const Eigen::Vector3d base =
          Eigen::Vector3d(post.north_m, post.east_m, -world.groundUp_m(post.north_m, post.east_m)) -
          gpu->origin_ned;
      const double h = post.heading_deg * 3.14159265358979323846 / 180.0;
      const Eigen::Vector3d f(std::cos(h), std::sin(h), 0.0), r(-std::sin(h), std::cos(h), 0.0);
      const Eigen::Vector3d up(0.0, 0.0, -post.height_m);
      const double s = 0.5 * post.size_m;
      const double sides[4][2] = {{-s, -s}, {-s, s}, {s, s}, {s, -s}};
      std::array<Eigen::Vector3d, 4> ring, top;
      for (std::size_t i = 0; i < 4; ++i) {
        ring[i] = base + sides[i][0] * f + sides[i][1] * r;
        top[i] = ring[i] + up;
      }
      const std::array<std::array<double, 2>, 4> none = {{{0, 0}, {0, 0}, {0, 0}, {0, 0}}};
      for (std::size_t i = 0; i < 4; ++i) {
        const std::size_t j = (i + 1) % 4;
        mesh.quad({ring[i], ring[j], top[j], top[i]}, none, kPostGrey[i % 2]);
      }
      mesh.quad(top, none, kPostGrey[2]);
    }
    gpu->vertices = static_cast<int>(mesh.data.size() / 6);
    glGenVertexArrays(1, &gpu->vertex_array);
    glBindVertexArray(gpu->vertex_array);
    glGenBuffers(1, &gpu->vertex_buffer);
    glBindBuffer(GL_ARRAY_BUFFER, gpu->vertex_buffer);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.data.size() * sizeof(float)),
                 mesh.data.data(), GL_STATIC_DRAW);
    const GLsizei stride = 6 * sizeof(float);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, nullptr);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, stride,
                          reinterpret_cast<const void*>(3 * sizeof(float)));
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(2, 1, GL_FLOAT, GL_FALSE, stride,
                          reinterpret_cast<const void*>(5 * sizeof(float)));
    glEnableVertexAttribArray(2);
    glBindVertexArray(0);
    const bool decoy = board.kind == "decoy";
    cv::Mat& rgb = patterns[{board.kind, decoy ? board.decoy_pattern : "", decoy ? board.seed : 0}];
    if (rgb.empty())
      cv::cvtColor(terrain::boardPattern(board, kPatternPx), rgb, cv::COLOR_GRAY2RGB);
    gpu->texture = uploadRgbTexture(rgb, GL_LINEAR_MIPMAP_LINEAR);
    boards_.push_back(std::move(gpu));
  }
  checkGl("uploading course boards");
}

int CourseBoardRenderer::draw(const Eigen::Matrix4d& clip_from_camera,
                              const Eigen::Isometry3d& T_world_cam, double near_m, double gain,
                              bool gray) {
  if (boards_.empty()) return 0;
  glEnable(GL_DEPTH_TEST);
  glUseProgram(program_);
  glUniform1f(glGetUniformLocation(program_, "u_gain"), static_cast<float>(gain));
  glUniform1i(glGetUniformLocation(program_, "u_gray"), gray ? 1 : 0);
  glUniform1i(glGetUniformLocation(program_, "u_texture"), 0);
  const GLint clip_from_local = glGetUniformLocation(program_, "u_clip_from_local");
  const Eigen::Matrix3d R_cam_world = T_world_cam.rotation().transpose();
  int drawn = 0;
  for (const auto& board : boards_) {
    Eigen::Matrix4d camera_from_local = Eigen::Matrix4d::Identity();
    camera_from_local.topLeftCorner<3, 3>() = R_cam_world;
    camera_from_local.topRightCorner<3, 1>() =
        R_cam_world * (board->origin_ned - T_world_cam.translation());
    // Far behind the camera: skip (clipping handles what is partly in front).
    if (camera_from_local(2, 3) < -2.0 - near_m) continue;
    const Eigen::Matrix4f clip = (clip_from_camera * camera_from_local).cast<float>();
    glUniformMatrix4fv(clip_from_local, 1, GL_FALSE, clip.data());
    glBindTexture(GL_TEXTURE_2D, board->texture);
    glBindVertexArray(board->vertex_array);
    glDrawArrays(GL_TRIANGLES, 0, board->vertices);
    ++drawn;
  }
  glBindVertexArray(0);
  return drawn;
}

}  // namespace nadir::render
