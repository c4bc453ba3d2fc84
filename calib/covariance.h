#pragma once
// The covariance of a calibration's intrinsics from the Jacobian at the
// solution, for the lens models whose OpenCV solver does not report one
// (cv::fisheye::calibrate): Cov = s^2 (J^T J)^-1 over the intrinsics and every
// view's pose, the poses eliminated by the Schur complement, s^2 the residual
// variance per image axis, sum r^2 / (residuals - parameters) with 2 residuals
// per corner.
//
// cv::calibrateCamera's stdDeviationsIntrinsics is the same product except
// that its s^2 divides by (corners - parameters), about twice too few: its
// standard deviations are sqrt((corners - P) / (2 corners - P)) times ours.

#include <vector>

#include <Eigen/Core>

namespace nadir::calib {

// One view at the solution: residuals (projected - observed, px; x and y of
// each corner in turn) and their derivatives.
struct ViewJacobian {
  Eigen::VectorXd residuals_px;
  Eigen::MatrixXd d_intrinsics;  // residuals x free intrinsics
  Eigen::MatrixXd d_pose;        // residuals x 6 (rvec, tvec)
};

struct IntrinsicCovariance {
  Eigen::MatrixXd covariance;  // free intrinsics x free intrinsics
  double sigma2_px2 = 0.0;     // residual variance per axis
  int residuals = 0;           // 2 per corner
  int parameters = 0;          // free intrinsics + 6 per view
  bool ok = false;             // false when J^T J is singular (the views do not fix them)
};

// Throws std::invalid_argument when the views' matrices do not agree in size
// or there are not more residuals than parameters.
IntrinsicCovariance intrinsicCovariance(const std::vector<ViewJacobian>& views);

}  // namespace nadir::calib
