#pragma once
// The windowed photometric bundle adjustment: the poses and affine brightness
// of the key-frames in the window and the inverse depths of the points they
// host, optimised jointly on the Huber-weighted photometric error of every
// point in every other key-frame that sees it (Levenberg-Marquardt, points
// eliminated by the Schur complement). The oldest key-frame is held fixed:
// the window's pose gauge. The scale comes from the rangefinder: points near
// its ray in a key-frame with a range carry a prior on their depth.

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "core/params.h"
#include "nodes/vo_direct/camera_model.h"
#include "nodes/vo_direct/frame_tracker.h"
#include "nodes/vo_direct/image_pyramid.h"

namespace nadir::vo {

struct WindowOptimizerParams {
  int iterations = 6;
  double huber_threshold = 9.0;
  double gradient_weight_c = 50.0;
  // The photometric noise every prior is weighed against, intensity.
  double photometric_sigma = 4.0;
  // A point's residual block in a key-frame is an outlier when its RMS
  // residual exceeds this at the start of the optimisation.
  double outlier_rms = 12.0;
  // Each key-frame's brightness stays near its tracking estimate.
  double affine_prior_sigma_a = 0.1;
  double affine_prior_sigma_b = 10.0;
  // A weak prior on each point's inverse depth (relative), so that a point no
  // other key-frame sees yet stays where it was made.
  double idepth_prior_sigma = 1.0;
  // The rangefinder's prior on the log depth of the points near its ray.
  double range_prior_sigma = 0.02;

  void visit(core::ParamVisitor& v);
};

struct WindowFrame {
  Eigen::Isometry3d T_cam_world = Eigen::Isometry3d::Identity();
  AffineBrightness affine;
  AffineBrightness affine_prior;          // the prior's centre
  const ImagePyramid* pyramid = nullptr;  // level 0 with gradients
  bool fixed = false;
};

struct WindowPoint {
  int host = 0;        // index in the frames
  float x = 0, y = 0;  // level-0 pixel in the host
  float idepth = 0;
  float idepth_prior = 0;  // the prior's centre
  // The depth the rangefinder implies here (inverse, in the host); 0: none.
  float idepth_range = 0;
  std::array<float, kPatternSize> intensities{};   // the host's
  std::array<float, kPatternSize> weights{};       // gradientWeight in the host
  Eigen::Vector3f ray = Eigen::Vector3f::UnitZ();  // through (x, y) in the host, z = 1
  // Set by the optimiser: most of its residual blocks were outliers.
  bool bad = false;
};

struct WindowStats {
  double rms_start = 0.0;  // RMS photometric residual over the inlier blocks
  double rms_end = 0.0;
  int blocks = 0;  // point-in-key-frame residual blocks in the image
  int outlier_blocks = 0;
  int iterations = 0;  // accepted steps
  int bad_points = 0;
};

// Fills a point's ray, intensities and weights from its host's level 0
// (which needs gradients).
void preparePoint(WindowPoint& point, const ImagePyramid& host, const cv::Matx33d& K,
                  const WindowOptimizerParams& params);

WindowStats optimizeWindow(std::vector<WindowFrame>& frames, std::vector<WindowPoint>& points,
                           const cv::Matx33d& K, const WindowOptimizerParams& params);

}  // namespace nadir::vo
