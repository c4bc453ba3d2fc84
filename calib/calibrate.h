#pragma once
// Camera calibration from checkerboard views: OpenCV's solvers (the pinhole
// with radial-tangential distortion through cv::calibrateCamera, the fisheye
// through cv::fisheye::calibrate), with what a user needs to trust the result:
// the standard deviation of every intrinsic, outlier views removed and named,
// the worst corners, and a held-out error that shows whether the views were
// enough.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

#include "calib/board.h"

namespace nadir::calib {

enum class LensModel {
  kRadtan,   // pinhole, k1 k2 p1 p2 k3 (cv::calibrateCamera, cv::projectPoints)
  kFisheye,  // equidistant, k1 k2 k3 k4 (cv::fisheye)
};
// "radtan" or "fisheye".
const char* lensModelName(LensModel model);
std::optional<LensModel> lensModelFromName(std::string_view name);

struct View {
  // Row-major as boardObjectPoints (Detection::corners_px).
  std::vector<cv::Point2f> corners_px;
  std::string name;  // for reports, e.g. the image's file name; may be empty
};

struct CalibOptions {
  LensModel model = LensModel::kRadtan;
  // Radtan only (the fisheye solver has no such options; setting one with the
  // fisheye model is an error): hold k3 at 0; hold fx / fy at aspect_ratio;
  // hold p1 = p2 = 0.
  bool fix_k3 = false;
  bool fix_aspect_ratio = false;
  double aspect_ratio = 1.0;
  bool zero_tangential = false;
  // After the first solve, views whose RMS exceeds max(median + outlier_mads *
  // 1.4826 MAD, outlier_floor_px) over the views are dropped and the solve
  // redone. The floor keeps views a good lens model explains (real photographs:
  // 0.2 to 0.35 px per view) when the views agree so well that the MAD is tiny.
  // Nothing is dropped if fewer than 3 views would remain.
  bool reject_outliers = true;
  double outlier_mads = 3.0;
  double outlier_floor_px = 0.5;
  // How many of the largest corner residuals to report.
  int worst_corners = 10;
  // Held-out error over k = min(max_folds, views) folds; below 2: not computed.
  int max_folds = 5;
  // The solver's iteration limit (OpenCV's default is 30); its change limit
  // is DBL_EPSILON, OpenCV's default.
  int max_iterations = 100;
};

// One standard deviation of each intrinsic, px for fx fy cx cy; 0 for a value
// held fixed. From J^T J at the solution with the residual variance per image
// axis (covariance.h; cv::calibrateCamera's own figures are rescaled to it).
struct IntrinsicStdDevs {
  double fx_px = 0.0;
  double fy_px = 0.0;
  double cx_px = 0.0;
  double cy_px = 0.0;
  std::vector<double> distortion;  // in Calibration::distortion's order
};

struct CornerResidual {
  int view = 0;    // index into the views given to calibrate
  int corner = 0;  // index into that view's corners_px
  double residual_px = 0.0;
};

struct RejectedView {
  int view = 0;         // index into the views given to calibrate
  double rms_px = 0.0;  // in the first solve
};

// k-fold held-out error: the kept views are dealt into k folds (view j of
// views_used to fold j mod k); each fold's views are left out of a calibration
// of the others and then, given that calibration's intrinsics, only their pose
// is solved (cv::solvePnP). Held-out RMS well above the training RMS means the
// intrinsics follow the views' noise: too few or too similar views.
struct HeldOutError {
  int folds = 0;                        // 0 = not computed
  int failed_folds = 0;                 // folds whose calibration failed (their views are left out)
  double mean_rms_px = 0.0;             // mean of per_view_rms_px over the views with a value
  double mean_training_rms_px = 0.0;    // mean of the folds' calibration RMS
  std::vector<double> per_view_rms_px;  // aligned with Calibration::views_used; NaN if failed
};

struct Calibration {
  LensModel model = LensModel::kRadtan;
  cv::Size image_size;
  cv::Matx33d camera_matrix = cv::Matx33d::eye();
  std::vector<double> distortion;  // radtan: k1 k2 p1 p2 k3; fisheye: k1 k2 k3 k4
  int opencv_flags = 0;            // as passed to the OpenCV solver
  double aspect_ratio = 0.0;       // fx / fy held fixed; 0 = not fixed

  double rms_px = 0.0;
  std::vector<int> views_used;          // indices into the views given, kept after rejection
  std::vector<double> per_view_rms_px;  // aligned with views_used
  std::vector<cv::Vec3d> rvecs;         // board -> camera, aligned with views_used
  std::vector<cv::Vec3d> tvecs;         // m
  // Missing when J^T J is singular: the views do not determine the intrinsics.
  std::optional<IntrinsicStdDevs> std_devs;
  std::vector<CornerResidual> worst_corners;  // largest first

  double first_rms_px = 0.0;          // before outlier rejection
  double outlier_threshold_px = 0.0;  // 0 when rejection was off
  std::vector<RejectedView> rejected;
  HeldOutError held_out;
};

// Throws std::invalid_argument for fewer than 3 views, a view whose corner
// count is not the board's, a non-finite corner, an image size <= 0, or
// options that do not fit the model; std::runtime_error when the solver fails.
Calibration calibrate(const std::vector<View>& views, const BoardSpec& board, cv::Size image_size,
                      const CalibOptions& options = {});

// The OpenCV flags calibrate passes to the solver for these options.
int openCvFlags(const CalibOptions& options);

// Pixel positions of board points seen by a camera with this calibration at
// (rvec, tvec).
std::vector<cv::Point2f> projectBoardPoints(const Calibration& calibration,
                                            const std::vector<cv::Point3f>& points_board,
                                            const cv::Vec3d& rvec, const cv::Vec3d& tvec);
// Normalised undistorted image points (x/z, y/z) of pixels.
std::vector<cv::Point2d> undistortToNormalised(const Calibration& calibration,
                                               const std::vector<cv::Point2d>& pixels);

}  // namespace nadir::calib
