#pragma once
// Local bundle adjustment for the feature-based VO: refines camera poses and
// 3-D points by minimising the reprojection error of their observations in
// undistorted pinhole images, optionally with priors on the relative rotation
// of camera pairs (the IMU's rotation between frames).
//
// The cost: for every observation the reprojection error e = pi(K,
// T_world_cam^-1 p_world_m) - px, whitened by sigma_px and passed through a
// Huber loss of threshold huber_px (on e / sigma_px, so in px at sigma_px = 1);
// for every rotation prior the rotation vector of R_ab_prior^T R_ab /
// sigma_rad. The solver is Levenberg-Marquardt with Ceres Solver's trust-region
// rules, the points eliminated by the Schur complement and the cameras'
// reduced system solved dense; a camera moves by a rotation on its side and a
// shift of its centre (docs/vo_feature.md, "Local bundle adjustment").
//
// The gauge is the caller's: fixed cameras and points are held constant
// (fix two cameras, or one camera and a point, for monocular scale).

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/params.h"
#include "nodes/vo_feature/reprojection.h"

namespace nadir::vo {

struct BundleAdjustmentParams {
  // Levenberg-Marquardt iterations per solve.
  int max_iterations = 10;
  // Huber threshold on the whitened reprojection error e / sigma_px (ORB-SLAM
  // uses sqrt(5.991) = 2.45); 0 turns the robust loss off.
  double huber_px = 2.5;
  // After solving, observations with |e / sigma_px|^2 above this are flagged as
  // outliers (5.991: the 95 % quantile of chi-square with 2 degrees of
  // freedom).
  double outlier_chi2 = 5.991;
  // After flagging, solve again without the outliers (ORB-SLAM's second pass:
  // the Huber loss bounds an outlier's pull but does not remove it), and again
  // while the flags change, at most this many times; 0: one solve.
  int outlier_rounds = 2;
  // Threads evaluating the residuals and their Jacobians; the result does not
  // depend on them.
  int num_threads = 1;

  void visit(core::ParamVisitor& v);
};

struct BaCamera {
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  bool fixed = false;
};

struct BaPoint {
  Eigen::Vector3d p_world_m = Eigen::Vector3d::Zero();
  bool fixed = false;
};

// Point `point` seen by camera `camera` at pixel px (undistorted).
struct BaObservation {
  int camera = 0;
  int point = 0;
  Eigen::Vector2d px = Eigen::Vector2d::Zero();
  // Standard deviation of each pixel coordinate, px (e.g. 1.2^octave).
  double sigma_px = 1.0;
};

// A prior on the rotation between two cameras: R_ab = R_world_cam_a^T
// R_world_cam_b (camera b's axes in camera a), with an isotropic standard
// deviation sigma_rad on its rotation vector.
struct BaRotationPrior {
  int camera_a = 0;
  int camera_b = 0;
  Eigen::Quaterniond R_ab = Eigen::Quaterniond::Identity();
  double sigma_rad = 0.01;
  // The error's part about camera a's z axis (for an absolute attitude, a
  // with the world's axes: about down, the heading) has this sigma; 0: sigma_rad.
  double sigma_about_a_z_rad = 0.0;
};

struct BaProblem {
  BaIntrinsics K;
  std::vector<BaCamera> cameras;
  std::vector<BaPoint> points;
  std::vector<BaObservation> observations;
  std::vector<BaRotationPrior> rotation_priors;
};

struct BaResult {
  // The last solve converged (false also when max_iterations ran out).
  bool converged = false;
  // Levenberg-Marquardt iterations of all solves (successful and unsuccessful steps).
  int iterations = 0;
  // Root mean square of the reprojection error per image coordinate, px,
  // before and after solving, over the observations not flagged as outliers
  // (0 when there are none).
  double initial_rmse_px = 0.0;
  double final_rmse_px = 0.0;
  // Per observation: an outlier after solving (chi-square test), or skipped
  // because the point was behind the camera.
  std::vector<bool> outlier;
  int num_outliers = 0;
  // A line per solve (steps, cost before and after, how it ended) and the
  // outlier count.
  std::string summary;
};

// Refines the non-fixed cameras and points of `problem` in place (a camera
// with rotation priors but no observations: its rotation only; one with
// neither, and a point without observations, stay as they are). Observations
// of points at or behind a camera's image plane at the start are skipped and
// flagged. Throws std::invalid_argument on an index out of range, a
// non-positive sigma or focal length, or a prior between a camera and itself.
BaResult bundleAdjust(BaProblem& problem, const BundleAdjustmentParams& params);

}  // namespace nadir::vo
