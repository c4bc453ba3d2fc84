#pragma once
// Direct alignment of a new frame to the newest key-frame: coarse-to-fine
// Levenberg-Marquardt on SE(3) and an affine brightness (a, b) over the
// key-frame's points with known inverse depth, minimising Huber-weighted
// photometric residuals over a pixel pattern.

#include <array>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/params.h"
#include "nodes/vo_direct/camera_model.h"
#include "nodes/vo_direct/image_pyramid.h"

namespace nadir::vo {

// Intensity = e^a * irradiance + b, per frame. Two frames i, j are compared
// through it symmetrically: r = e^(-(a_j - a_i)/2) (I_j - b_j) - e^((a_j - a_i)/2) (I_i - b_i),
// the residual e^(-(a_j - a_i)/2) times I_j - predicted I_j. Least squares on the one-sided
// form is a regression of I_j on I_i, whose gain shrinks by the share of
// noise in I_i (resampling, sensor noise); the symmetric form estimates the
// ratio of their contrasts and does not drift from key-frame to key-frame.
struct AffineBrightness {
  double a = 0.0;
  double b = 0.0;
};

struct TrackerParams {
  // The finest pyramid level aligned (0: full resolution).
  int finest_level = 1;
  // Levenberg-Marquardt iterations per level, at most.
  int max_iterations = 50;
  // Huber threshold on a residual, intensity levels.
  double huber_threshold = 9.0;
  // Gradient-dependent weight c^2 / (c^2 + |grad|^2): pixels on strong edges
  // are less sure (interpolation, blur).
  double gradient_weight_c = 50.0;
  // Priors on the frame's brightness change from the key-frame (a: log gain,
  // b: offset, intensity levels), against a photometric noise of
  // photometric_sigma: they keep (a, b) from running away on noise.
  double affine_prior_sigma_a = 0.2;
  double affine_prior_sigma_b = 20.0;
  double photometric_sigma = 4.0;
  // Stop a level when a step moves the image by less than this, in the level's
  // pixels (rotation and translation at the points' mean depth), and changes
  // the gain by less than this over 100.
  double convergence_px = 0.05;

  void visit(core::ParamVisitor& v);
};

// One reference pixel at one level: the ray through it (z = 1), the
// key-frame's intensities at its pattern pixels, its inverse depth in the key-frame.
struct TrackingPoint {
  Eigen::Vector3f ray;
  std::array<float, kPatternSize> intensities;
  std::array<float, kPatternSize> weights;  // gradientWeight at the key-frame's pixels
  float idepth = 0;
  float x = 0, y = 0;  // level pixel
};

struct TrackingReference {
  std::vector<std::vector<TrackingPoint>> levels;  // index: pyramid level
  std::vector<PinholeLevel> cameras;
  AffineBrightness affine;  // the key-frame's
  float mean_idepth = 0;

  bool empty() const { return levels.empty(); }
};

// Points of the key-frame at level-0 pixel (x, y) with inverse depth; each
// level keeps one point per pixel (the mean inverse depth of those falling in
// it). The key-frame needs gradients at those levels.
struct DepthPixel {
  float x = 0, y = 0, idepth = 0;
};
TrackingReference makeTrackingReference(const ImagePyramid& keyframe, const cv::Matx33d& K,
                                        const std::vector<DepthPixel>& points,
                                        const AffineBrightness& affine, int finest_level,
                                        int coarsest_level, double gradient_weight_c);

struct TrackResult {
  Eigen::Isometry3d T_frame_ref = Eigen::Isometry3d::Identity();
  AffineBrightness affine;  // the frame's
  // At the finest level: RMS of the residuals (Huber's cost: robust, not
  // weighted by the gradient; intensity), the
  // share of points whose pattern stayed in the image, and those used.
  double rms = 0.0;
  double in_image_share = 0.0;
  int points = 0;
  int iterations = 0;
  // The same at the coarsest level (a bad start shows there first).
  double coarse_rms = 0.0;
  // How well the image fixes the pose: the 1-sigma angle, rad, by which the
  // pose's least-determined rotation and translation (at the points' mean
  // depth) turn the rays, from the finest level's Gauss-Newton covariance
  // scaled by the residuals' RMS. Low texture leaves directions the image
  // cannot tell. An angle, so that one threshold serves every resolution.
  double pose_sigma_rad = 0.0;
};

// frame needs gradients at every level the reference holds.
TrackResult trackFrame(const TrackingReference& reference, const ImagePyramid& frame,
                       const Eigen::Isometry3d& T_frame_ref_guess,
                       const AffineBrightness& affine_guess, const TrackerParams& params);

}  // namespace nadir::vo
