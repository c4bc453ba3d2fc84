#pragma once
// The virtual checkerboard: nadir's own camera (render::CameraRenderer, with
// the lens's distortion, noise and every other effect its CameraParams turn
// on) looking at a checkerboard (terrain::CheckerboardWorld) from poses that
// cover the view the way a person waving a board in front of a camera does:
// the board near every part of the image, near and far, tilted up to
// max_tilt_deg. The board is rendered, never drawn from its known corners.
// Needs EGL (it makes its own headless context).

#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "core/params.h"
#include "render/camera_model.h"
#include "render/camera_renderer.h"
#include "terrain/checkerboard_world.h"

namespace nadir::calib {

struct VirtualViewParams {
  // Poses the board is seen from, in order.
  int views = 60;
  // The board's width (with its white margin) as a share of the image's,
  // from the nearest view to the farthest.
  double max_fill = 0.8;
  double min_fill = 0.3;
  // Largest angle between the board's normal and the optical axis, deg.
  double max_tilt_deg = 45.0;
  // Largest turn of the board about the optical axis, deg.
  double max_roll_deg = 30.0;
  // The whole board stays this far inside the image, px.
  double border_px = 8.0;
  int seed = 1;

  void visit(core::ParamVisitor& v);
};

// Camera poses (T_world_cam, world frame NED, the board on the ground at the
// origin) from which the whole board with its margin is in the image, its
// centre going over a 3 x 3 grid of the image, near and far, and tilted.
// Deterministic for a seed. Throws std::invalid_argument when a board of that
// size cannot be placed in the image (a fill range too large for the lens).
std::vector<Eigen::Isometry3d> coveringPoses(const terrain::CheckerboardParams& board,
                                             const render::CameraIntrinsics& intrinsics,
                                             const VirtualViewParams& params);

// The inner corners of the board in the world frame, row-major from the
// south-west one (row along north, column along east).
std::vector<Eigen::Vector3d> boardCorners_world(const terrain::CheckerboardWorld& world);

// Its OpenGL context is made current on the constructing thread and stays
// so: construct it and render on the same thread.
class VirtualCheckerboard {
 public:
  // The camera's near and far planes are set from the poses' distances (a
  // board a few centimetres across is seen from a few decimetres).
  VirtualCheckerboard(const terrain::CheckerboardParams& board, const render::CameraParams& camera,
                      const VirtualViewParams& views);
  ~VirtualCheckerboard();
  VirtualCheckerboard(const VirtualCheckerboard&) = delete;
  VirtualCheckerboard& operator=(const VirtualCheckerboard&) = delete;

  int size() const { return static_cast<int>(poses_.size()); }
  // View i (0 <= i < size()), stamped i / 10 s apart.
  render::RenderedImage render(int i);
  const std::vector<Eigen::Isometry3d>& poses() const { return poses_; }
  const render::CameraIntrinsics& intrinsics() const;
  const terrain::CheckerboardWorld& world() const { return *world_; }

 private:
  struct Gl;
  std::shared_ptr<terrain::CheckerboardWorld> world_;
  std::vector<Eigen::Isometry3d> poses_;
  std::unique_ptr<Gl> gl_;
};

}  // namespace nadir::calib
