#pragma once
// A virtual camera: renders the terrain from a pose into an offscreen
// framebuffer, applies motion blur, rolling shutter, lens distortion,
// vignetting, auto-exposure, sensor noise and a response curve, and reads the image
// (and optionally per-pixel depth) back. Deterministic: the same pose, utime
// and parameters give bit-identical images.

#include <cstdint>
#include <memory>

#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

#include "render/camera_model.h"
#include "render/terrain_renderer.h"

namespace nadir::render {

// The camera's motion about the frame's time, in its optical frame: the pose
// at time t from the frame's is T_frame_t = (exp(t omega), t v).
struct CameraMotion {
  Eigen::Vector3d omega_cam_rps = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_cam_mps = Eigen::Vector3d::Zero();
};

struct RenderedImage {
  std::int64_t utime = 0;
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  // CV_8UC1 (gray8) or CV_8UC3 with R first (rgb8); row 0 is the image top.
  cv::Mat image;
  // CV_32FC1 depth along the optical axis, m, +inf where no ground was hit;
  // empty unless asked for.
  cv::Mat depth_m;
  DrawStats stats;
};

class CameraRenderer {
 public:
  // Needs the GL context the terrain renderer was made in, current.
  CameraRenderer(TerrainRenderer& terrain, const CameraParams& params);
  ~CameraRenderer();
  CameraRenderer(const CameraRenderer&) = delete;
  CameraRenderer& operator=(const CameraRenderer&) = delete;

  // With motion blur or rolling shutter on, motion says how the camera moves
  // about T_world_cam (none: it stands still); the depth is the frame time's.
  RenderedImage render(const Eigen::Isometry3d& T_world_cam, std::int64_t utime,
                       bool with_depth = false, const CameraMotion& motion = {});

  const CameraIntrinsics& intrinsics() const { return intrinsics_; }
  const CameraParams& params() const { return params_; }
  // The auto-exposure's gain for the last frame (1 without auto-exposure).
  double exposureGain() const { return ae_gain_; }

 private:
  struct Target;
  void createTargets();
  double vignettingK() const;
  // The auto-exposure's gain for a frame at utime, from the frame before.
  double exposureGain(std::int64_t utime);
  // Tells the terrain where the camera is likely to look next (tiles made ahead).
  void expectNextViews(const DrawView& view, std::int64_t utime);

  TerrainRenderer& terrain_;
  CameraParams params_;
  CameraIntrinsics intrinsics_;
  // The undistorted camera the scene is drawn with (wider when distortion is on).
  CameraIntrinsics scene_intrinsics_;
  bool post_pass_ = false;
  std::unique_ptr<Target> scene_;
  std::unique_ptr<Target> output_;
  unsigned int post_program_ = 0;
  unsigned int motion_program_ = 0;
  unsigned int motion_indices_ = 0;
  int motion_cells_x_ = 0;
  int motion_index_count_ = 0;
  unsigned int post_vertex_array_ = 0;
  unsigned int distortion_map_ = 0;
  // Scene pixel coordinates of each output pixel (for depth with distortion).
  cv::Mat map_x_, map_y_;
  double ae_gain_ = 1.0;
  double ae_last_mean_counts_ = 0.0;
  std::int64_t ae_last_utime_ = -1;
  // The last frame's camera position and time, for where it will be next.
  Eigen::Vector3d last_p_world_cam_m_ = Eigen::Vector3d::Zero();
  std::int64_t last_utime_ = -1;
};

}  // namespace nadir::render
