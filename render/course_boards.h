#pragma once
// Upright course boards (terrain/course.h) drawn in 3D with a depth test, so
// that posts and boards hide what stands behind them: each board's pattern on
// its front face, a plain back, and its posts as boxes. Needs a current OpenGL
// 4.5 core context.

#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "terrain/course.h"
#include "terrain/world.h"

namespace nadir::render {

class CourseBoardRenderer {
 public:
  CourseBoardRenderer();
  ~CourseBoardRenderer();
  CourseBoardRenderer(const CourseBoardRenderer&) = delete;
  CourseBoardRenderer& operator=(const CourseBoardRenderer&) = delete;

  // The boards drawn from now on (replacing earlier ones), standing on the
  // world's ground.
  void setBoards(const std::vector<terrain::CourseBoard>& boards, const terrain::World& world);
  // Draws them into the current framebuffer over what is there, depth-tested;
  // returns the boards drawn.
  int draw(const Eigen::Matrix4d& clip_from_camera, const Eigen::Isometry3d& T_world_cam,
           double near_m, double gain, bool gray);
  std::size_t size() const { return boards_.size(); }

 private:
  struct GpuBoard;
  std::vector<std::unique_ptr<GpuBoard>> boards_;
  unsigned int program_ = 0;
};

}  // namespace nadir::render
