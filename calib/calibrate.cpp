#include "calib/calibrate.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>

#include "calib/covariance.h"

namespace nadir::calib {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// What one run of an OpenCV solver gives, for a subset of the views.
struct Solve {
  cv::Matx33d camera_matrix = cv::Matx33d::eye();
  std::vector<double> distortion;
  std::vector<cv::Vec3d> rvecs, tvecs;
  double rms_px = 0.0;
  std::vector<double> per_view_rms_px;
  std::optional<IntrinsicStdDevs> std_devs;
};

using Corners = std::vector<std::vector<cv::Point2f>>;
using Objects = std::vector<std::vector<cv::Point3f>>;

cv::TermCriteria criteria(const CalibOptions& options) {
  return {cv::TermCriteria::COUNT + cv::TermCriteria::EPS, options.max_iterations, DBL_EPSILON};
}

std::vector<cv::Point2f> project(LensModel model, const std::vector<cv::Point3f>& points,
                                 const cv::Vec3d& rvec, const cv::Vec3d& tvec,
                                 const cv::Matx33d& camera_matrix,
                                 const std::vector<double>& distortion) {
  std::vector<cv::Point2f> pixels;
  if (model == LensModel::kFisheye)
    cv::fisheye::projectPoints(points, pixels, rvec, tvec, camera_matrix, distortion);
  else
    cv::projectPoints(points, rvec, tvec, camera_matrix, distortion, pixels);
  return pixels;
}

double rmsOf(const std::vector<cv::Point2f>& projected, const std::vector<cv::Point2f>& observed) {
  double sum = 0.0;
  for (std::size_t i = 0; i < observed.size(); ++i) {
    const double dx = projected[i].x - observed[i].x, dy = projected[i].y - observed[i].y;
    sum += dx * dx + dy * dy;
  }
  return std::sqrt(sum / static_cast<double>(observed.size()));
}

Solve solveRadtan(const Objects& objects, const Corners& corners, cv::Size image_size,
                  const CalibOptions& options) {
  cv::Mat camera_matrix = cv::Mat::eye(3, 3, CV_64F);
  // With CALIB_FIX_ASPECT_RATIO OpenCV keeps the ratio of the initial fx, fy.
  if (options.fix_aspect_ratio) camera_matrix.at<double>(0, 0) = options.aspect_ratio;
  cv::Mat distortion, std_intrinsics, std_extrinsics, per_view;
  std::vector<cv::Mat> rvecs, tvecs;
  Solve solve;
  solve.rms_px = cv::calibrateCamera(objects, corners, image_size, camera_matrix, distortion, rvecs,
                                     tvecs, std_intrinsics, std_extrinsics, per_view,
                                     openCvFlags(options), criteria(options));
  solve.camera_matrix = cv::Matx33d(camera_matrix);
  distortion = distortion.reshape(1, 1);
  for (int i = 0; i < 5; ++i) solve.distortion.push_back(distortion.at<double>(0, i));
  for (std::size_t v = 0; v < rvecs.size(); ++v) {
    solve.rvecs.emplace_back(rvecs[v]);
    solve.tvecs.emplace_back(tvecs[v]);
    solve.per_view_rms_px.push_back(per_view.at<double>(static_cast<int>(v)));
  }

  // OpenCV's s^2 divides by (corners - P); ours by (2 corners - P) (covariance.h).
  int corners_total = 0;
  for (const auto& view : corners) corners_total += static_cast<int>(view.size());
  const int free_intrinsics = (options.fix_aspect_ratio ? 3 : 4) + 2 + (options.fix_k3 ? 0 : 1) +
                              (options.zero_tangential ? 0 : 2);
  const int parameters = free_intrinsics + 6 * static_cast<int>(corners.size());
  const double* sd = std_intrinsics.ptr<double>();
  if (corners_total > parameters && std::isfinite(sd[1]) && sd[1] > 0.0) {
    const double rescale =
        std::sqrt(double(corners_total - parameters) / double(2 * corners_total - parameters));
    IntrinsicStdDevs s;
    s.fy_px = rescale * sd[1];
    // fx = aspect_ratio fy exactly when the ratio is held; OpenCV reports 0.
    s.fx_px = options.fix_aspect_ratio ? options.aspect_ratio * s.fy_px : rescale * sd[0];
    s.cx_px = rescale * sd[2];
    s.cy_px = rescale * sd[3];
    for (int i = 4; i < 9; ++i) s.distortion.push_back(rescale * sd[i]);
    solve.std_devs = s;
  }
  return solve;
}

// Residuals and Jacobian of one fisheye view: columns of
// cv::fisheye::projectPoints' Jacobian are fx fy cx cy k1..k4 rvec tvec skew.
ViewJacobian fisheyeJacobian(const std::vector<cv::Point3f>& points,
                             const std::vector<cv::Point2f>& observed, const cv::Vec3d& rvec,
                             const cv::Vec3d& tvec, const cv::Matx33d& camera_matrix,
                             const std::vector<double>& distortion) {
  std::vector<cv::Point2d> projected;
  cv::Mat jacobian;
  std::vector<cv::Point3d> points_d(points.begin(), points.end());
  cv::fisheye::projectPoints(points_d, projected, rvec, tvec, camera_matrix, distortion, 0.0,
                             jacobian);
  const int n = static_cast<int>(points.size());
  ViewJacobian view;
  view.residuals_px.resize(2 * n);
  view.d_intrinsics.resize(2 * n, 8);
  view.d_pose.resize(2 * n, 6);
  for (int i = 0; i < n; ++i) {
    view.residuals_px(2 * i) = projected[i].x - observed[i].x;
    view.residuals_px(2 * i + 1) = projected[i].y - observed[i].y;
  }
  for (int r = 0; r < 2 * n; ++r) {
    for (int c = 0; c < 8; ++c) view.d_intrinsics(r, c) = jacobian.at<double>(r, c);
    for (int c = 0; c < 6; ++c) view.d_pose(r, c) = jacobian.at<double>(r, 8 + c);
  }
  return view;
}

Solve solveFisheye(const Objects& objects, const Corners& corners, cv::Size image_size,
                   const CalibOptions& options, bool want_std_devs) {
  cv::Matx33d camera_matrix;
  cv::Vec4d distortion;
  std::vector<cv::Vec3d> rvecs, tvecs;
  cv::fisheye::calibrate(objects, corners, image_size, camera_matrix, distortion, rvecs, tvecs,
                         openCvFlags(options), criteria(options));
  Solve solve;
  solve.camera_matrix = camera_matrix;
  solve.distortion.assign(distortion.val, distortion.val + 4);
  solve.rvecs = rvecs;
  solve.tvecs = tvecs;
  double sum = 0.0;
  int total = 0;
  for (std::size_t v = 0; v < corners.size(); ++v) {
    const double rms = rmsOf(project(LensModel::kFisheye, objects[v], rvecs[v], tvecs[v],
                                     camera_matrix, solve.distortion),
                             corners[v]);
    solve.per_view_rms_px.push_back(rms);
    sum += rms * rms * static_cast<double>(corners[v].size());
    total += static_cast<int>(corners[v].size());
  }
  solve.rms_px = std::sqrt(sum / total);
  if (!want_std_devs) return solve;

  std::vector<ViewJacobian> jacobians;
  for (std::size_t v = 0; v < corners.size(); ++v)
    jacobians.push_back(fisheyeJacobian(objects[v], corners[v], rvecs[v], tvecs[v], camera_matrix,
                                        solve.distortion));
  const IntrinsicCovariance cov = intrinsicCovariance(jacobians);
  if (cov.ok) {
    IntrinsicStdDevs s;
    s.fx_px = std::sqrt(cov.covariance(0, 0));
    s.fy_px = std::sqrt(cov.covariance(1, 1));
    s.cx_px = std::sqrt(cov.covariance(2, 2));
    s.cy_px = std::sqrt(cov.covariance(3, 3));
    for (int i = 4; i < 8; ++i) s.distortion.push_back(std::sqrt(cov.covariance(i, i)));
    solve.std_devs = s;
  }
  return solve;
}

Solve solve(const Objects& objects, const Corners& corners, cv::Size image_size,
            const CalibOptions& options, bool want_std_devs) {
  try {
    Solve s = options.model == LensModel::kFisheye
                  ? solveFisheye(objects, corners, image_size, options, want_std_devs)
                  : solveRadtan(objects, corners, image_size, options);
    bool finite = std::isfinite(s.rms_px);
    for (int i = 0; i < 9; ++i) finite = finite && std::isfinite(s.camera_matrix.val[i]);
    for (double d : s.distortion) finite = finite && std::isfinite(d);
    if (!finite)
      throw std::runtime_error(std::string("calibrate: the ") + lensModelName(options.model) +
                               " solver returned values that are not finite on " +
                               std::to_string(corners.size()) + " views");
    return s;
  } catch (const cv::Exception& e) {
    throw std::runtime_error(std::string("calibrate: the ") + lensModelName(options.model) +
                             " solver failed on " + std::to_string(corners.size()) +
                             " views: " + e.what());
  }
}

// Pose of a held-out view given the intrinsics. Fisheye: cv::solvePnP on the
// undistorted points, then Gauss-Newton on the pixel residuals so that both
// models minimise the same error.
std::optional<std::pair<cv::Vec3d, cv::Vec3d>> solvePose(LensModel model,
                                                         const std::vector<cv::Point3f>& points,
                                                         const std::vector<cv::Point2f>& observed,
                                                         const cv::Matx33d& camera_matrix,
                                                         const std::vector<double>& distortion) {
  cv::Vec3d rvec, tvec;
  if (model == LensModel::kRadtan) {
    if (!cv::solvePnP(points, observed, camera_matrix, distortion, rvec, tvec, false,
                      cv::SOLVEPNP_ITERATIVE))
      return std::nullopt;
    return std::make_pair(rvec, tvec);
  }
  std::vector<cv::Point2f> normalised;
  cv::fisheye::undistortPoints(
      observed, normalised, camera_matrix, distortion, cv::noArray(), cv::noArray(),
      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 50, 1e-12));
  if (!cv::solvePnP(points, normalised, cv::Matx33d::eye(), cv::noArray(), rvec, tvec, false,
                    cv::SOLVEPNP_ITERATIVE))
    return std::nullopt;
  for (int iteration = 0; iteration < 10; ++iteration) {
    const ViewJacobian j = fisheyeJacobian(points, observed, rvec, tvec, camera_matrix, distortion);
    const Eigen::Matrix<double, 6, 6> jtj = j.d_pose.transpose() * j.d_pose;
    const Eigen::Matrix<double, 6, 1> step =
        jtj.ldlt().solve(-j.d_pose.transpose() * j.residuals_px);
    if (!step.allFinite()) return std::nullopt;
    for (int i = 0; i < 3; ++i) {
      rvec[i] += step(i);
      tvec[i] += step(3 + i);
    }
    if (step.norm() < 1e-12) break;
  }
  return std::make_pair(rvec, tvec);
}

HeldOutError heldOutError(const Objects& objects, const Corners& corners, cv::Size image_size,
                          const CalibOptions& options) {
  HeldOutError result;
  const int n = static_cast<int>(corners.size());
  const int k = std::min(options.max_folds, n);
  if (k < 2) return result;
  result.folds = k;
  result.per_view_rms_px.assign(n, kNaN);
  double training_sum = 0.0;
  for (int fold = 0; fold < k; ++fold) {
    Objects train_objects;
    Corners train_corners;
    for (int j = 0; j < n; ++j) {
      if (j % k == fold) continue;
      train_objects.push_back(objects[j]);
      train_corners.push_back(corners[j]);
    }
    std::optional<Solve> trained;
    try {
      trained = solve(train_objects, train_corners, image_size, options, false);
    } catch (const std::runtime_error&) {
      ++result.failed_folds;
      continue;
    }
    training_sum += trained->rms_px;
    for (int j = fold; j < n; j += k) {
      const auto pose = solvePose(options.model, objects[j], corners[j], trained->camera_matrix,
                                  trained->distortion);
      if (!pose) continue;
      result.per_view_rms_px[j] =
          rmsOf(project(options.model, objects[j], pose->first, pose->second,
                        trained->camera_matrix, trained->distortion),
                corners[j]);
    }
  }
  double sum = 0.0;
  int counted = 0;
  for (double rms : result.per_view_rms_px) {
    if (std::isnan(rms)) continue;
    sum += rms;
    ++counted;
  }
  result.mean_rms_px = counted > 0 ? sum / counted : kNaN;
  const int solved = k - result.failed_folds;
  result.mean_training_rms_px = solved > 0 ? training_sum / solved : kNaN;
  return result;
}

double median(std::vector<double> values) {
  const std::size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  const double upper = values[mid];
  if (values.size() % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(values.begin(), values.begin() + mid));
}

void validate(const std::vector<View>& views, const BoardSpec& board, cv::Size image_size,
              const CalibOptions& options) {
  validateBoard(board);
  if (views.size() < 3)
    throw std::invalid_argument("calibrate: " + std::to_string(views.size()) +
                                " views given; at least 3 are needed");
  for (std::size_t v = 0; v < views.size(); ++v) {
    const std::string which = "calibrate: view " + std::to_string(v) +
                              (views[v].name.empty() ? "" : " (" + views[v].name + ")");
    if (static_cast<int>(views[v].corners_px.size()) != board.cornerCount())
      throw std::invalid_argument(which + " has " + std::to_string(views[v].corners_px.size()) +
                                  " corners; the " + describeBoard(board) + " board has " +
                                  std::to_string(board.cornerCount()));
    for (const cv::Point2f& p : views[v].corners_px) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y))
        throw std::invalid_argument(which + " has a corner that is not a finite number");
    }
  }
  if (image_size.width <= 0 || image_size.height <= 0)
    throw std::invalid_argument("calibrate: image size " + std::to_string(image_size.width) + "x" +
                                std::to_string(image_size.height) + " is not positive");
  if (options.model == LensModel::kFisheye &&
      (options.fix_k3 || options.fix_aspect_ratio || options.zero_tangential))
    throw std::invalid_argument(
        "calibrate: fix_k3, fix_aspect_ratio and zero_tangential are radtan options; the fisheye "
        "model (k1..k4, no tangential terms) has none of them");
  if (options.fix_aspect_ratio &&
      !(options.aspect_ratio > 0.0 && std::isfinite(options.aspect_ratio)))
    throw std::invalid_argument(
        "calibrate: aspect_ratio = " + std::to_string(options.aspect_ratio) + " must be positive");
  if (!(options.outlier_floor_px >= 0.0) || !(options.outlier_mads > 0.0))
    throw std::invalid_argument("calibrate: outlier_floor_px must be >= 0 and outlier_mads > 0");
  if (options.worst_corners < 0 || options.max_iterations < 1)
    throw std::invalid_argument("calibrate: worst_corners must be >= 0 and max_iterations >= 1");
}

}  // namespace

const char* lensModelName(LensModel model) {
  return model == LensModel::kFisheye ? "fisheye" : "radtan";
}

std::optional<LensModel> lensModelFromName(std::string_view name) {
  if (name == "radtan") return LensModel::kRadtan;
  if (name == "fisheye") return LensModel::kFisheye;
  return std::nullopt;
}

int openCvFlags(const CalibOptions& options) {
  if (options.model == LensModel::kFisheye)
    return cv::fisheye::CALIB_RECOMPUTE_EXTRINSIC | cv::fisheye::CALIB_FIX_SKEW;
  int flags = 0;
  if (options.fix_k3) flags |= cv::CALIB_FIX_K3;
  if (options.fix_aspect_ratio) flags |= cv::CALIB_FIX_ASPECT_RATIO;
  if (options.zero_tangential) flags |= cv::CALIB_ZERO_TANGENT_DIST;
  return flags;
}

Calibration calibrate(const std::vector<View>& views, const BoardSpec& board, cv::Size image_size,
                      const CalibOptions& options) {
  validate(views, board, image_size, options);
  const std::vector<cv::Point3f> points = boardObjectPoints(board);

  std::vector<int> used(views.size());
  std::iota(used.begin(), used.end(), 0);
  auto subset = [&](const std::vector<int>& indices) {
    std::pair<Objects, Corners> s;
    for (int i : indices) {
      s.first.push_back(points);
      s.second.push_back(views[i].corners_px);
    }
    return s;
  };

  auto [objects, corners] = subset(used);
  Solve result = solve(objects, corners, image_size, options, true);

  Calibration calibration;
  calibration.first_rms_px = result.rms_px;
  if (options.reject_outliers) {
    const double med = median(result.per_view_rms_px);
    std::vector<double> deviations;
    for (double rms : result.per_view_rms_px) deviations.push_back(std::abs(rms - med));
    const double mad = median(deviations);
    calibration.outlier_threshold_px =
        std::max(med + options.outlier_mads * 1.4826 * mad, options.outlier_floor_px);
    std::vector<int> kept;
    std::vector<RejectedView> rejected;
    for (std::size_t j = 0; j < used.size(); ++j) {
      if (result.per_view_rms_px[j] > calibration.outlier_threshold_px)
        rejected.push_back({used[j], result.per_view_rms_px[j]});
      else
        kept.push_back(used[j]);
    }
    if (!rejected.empty() && kept.size() >= 3) {
      calibration.rejected = rejected;
      used = kept;
      std::tie(objects, corners) = subset(used);
      result = solve(objects, corners, image_size, options, true);
    }
  }

  calibration.model = options.model;
  calibration.image_size = image_size;
  calibration.camera_matrix = result.camera_matrix;
  calibration.distortion = result.distortion;
  calibration.opencv_flags = openCvFlags(options);
  calibration.aspect_ratio = options.fix_aspect_ratio ? options.aspect_ratio : 0.0;
  calibration.rms_px = result.rms_px;
  calibration.views_used = used;
  calibration.per_view_rms_px = result.per_view_rms_px;
  calibration.rvecs = result.rvecs;
  calibration.tvecs = result.tvecs;
  calibration.std_devs = result.std_devs;

  std::vector<CornerResidual> residuals;
  for (std::size_t j = 0; j < used.size(); ++j) {
    const std::vector<cv::Point2f> projected =
        project(options.model, points, result.rvecs[j], result.tvecs[j], result.camera_matrix,
                result.distortion);
    for (std::size_t i = 0; i < points.size(); ++i)
      residuals.push_back({used[j], static_cast<int>(i), cv::norm(projected[i] - corners[j][i])});
  }
  const std::size_t worst = std::min<std::size_t>(options.worst_corners, residuals.size());
  std::partial_sort(residuals.begin(), residuals.begin() + worst, residuals.end(),
                    [](const CornerResidual& a, const CornerResidual& b) {
                      return a.residual_px > b.residual_px;
                    });
  calibration.worst_corners.assign(residuals.begin(), residuals.begin() + worst);

  calibration.held_out = heldOutError(objects, corners, image_size, options);
  return calibration;
}

std::vector<cv::Point2f> projectBoardPoints(const Calibration& calibration,
                                            const std::vector<cv::Point3f>& points_board,
                                            const cv::Vec3d& rvec, const cv::Vec3d& tvec) {
  return project(calibration.model, points_board, rvec, tvec, calibration.camera_matrix,
                 calibration.distortion);
}

std::vector<cv::Point2d> undistortToNormalised(const Calibration& calibration,
                                               const std::vector<cv::Point2d>& pixels) {
  std::vector<cv::Point2d> normalised;
  if (pixels.empty()) return normalised;
  const cv::TermCriteria precise(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-14);
  if (calibration.model == LensModel::kFisheye)
    cv::fisheye::undistortPoints(pixels, normalised, calibration.camera_matrix,
                                 calibration.distortion, cv::noArray(), cv::noArray(), precise);
  else
    cv::undistortPoints(pixels, normalised, calibration.camera_matrix, calibration.distortion,
                        cv::noArray(), cv::noArray(), precise);
  return normalised;
}

}  // namespace nadir::calib
