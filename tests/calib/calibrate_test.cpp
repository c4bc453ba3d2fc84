// The calibration against numbers worked out apart from it: OpenCV's sample
// result on its own photographs, cv::calibrateCamera called directly, and a
// software camera whose lens is known exactly (synthetic_board.h).

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/calib3d.hpp>

#include "calib/board.h"
#include "calib/calibrate.h"
#include "calib/covariance.h"
#include "tests/calib/opencv_photos.h"
#include "tests/calib/synthetic_board.h"

namespace nadir::calib {
namespace {

const BoardSpec kPhotoBoard{.inner_cols = 9, .inner_rows = 6, .square_m = 0.025};
const cv::Size kPhotoSize(640, 480);

// OpenCV's sample on the 13 photographs (tests/data/calib/opencv_left/left_intrinsics.yml).
constexpr double kSampleF = 5.3591573396163199e+02;
constexpr double kSampleCx = 3.4228315473308373e+02;
constexpr double kSampleCy = 2.3557082909788173e+02;
constexpr double kSampleRms = 3.9259098975581364e-01;

// The photographs' corners by our detector, and by the sample's; each
// computed once per process, only when a test needs it.
const std::vector<View>& ourPhotoViews() {
  static const std::vector<View> views = [] {
    std::vector<View> v;
    for (const std::string& name : test::photoNames()) {
      if (const std::optional<Detection> d = detectBoard(test::loadPhoto(name), kPhotoBoard))
        v.push_back({d->corners_px, name});
    }
    return v;
  }();
  return views;
}

const std::vector<View>& samplePhotoViews() {
  static const std::vector<View> views = [] {
    std::vector<View> v;
    for (const std::string& name : test::photoNames()) {
      const std::vector<cv::Point2f> corners = test::sampleCorners(test::loadPhoto(name));
      if (!corners.empty()) v.push_back({corners, name});
    }
    return v;
  }();
  return views;
}

// cv::calibrateCamera on the same corners, flags and termination as calibrate.
struct Direct {
  cv::Mat camera_matrix, distortion, std_intrinsics, per_view;
  double rms = 0.0;
};
Direct calibrateDirectly(const std::vector<View>& views, const BoardSpec& board, cv::Size size,
                         int flags, double aspect_ratio) {
  std::vector<std::vector<cv::Point3f>> objects(views.size(), boardObjectPoints(board));
  std::vector<std::vector<cv::Point2f>> corners;
  for (const View& v : views) corners.push_back(v.corners_px);
  Direct d;
  d.camera_matrix = cv::Mat::eye(3, 3, CV_64F);
  d.camera_matrix.at<double>(0, 0) = aspect_ratio;
  std::vector<cv::Mat> rvecs, tvecs;
  cv::Mat std_extrinsics;
  d.rms = cv::calibrateCamera(
      objects, corners, size, d.camera_matrix, d.distortion, rvecs, tvecs, d.std_intrinsics,
      std_extrinsics, d.per_view, flags,
      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, DBL_EPSILON));
  d.distortion = d.distortion.reshape(1, 1);
  return d;
}

void expectRelative(double actual, double expected, double relative, const char* what) {
  EXPECT_NEAR(actual, expected, relative * std::abs(expected)) << what;
}

CalibOptions sampleOptions() {
  CalibOptions options;
  options.fix_aspect_ratio = true;  // the sample's flags: CALIB_FIX_ASPECT_RATIO, aspect 1
  options.aspect_ratio = 1.0;
  return options;
}

// ---- Real photographs -------------------------------------------------------

// Both our detector and the sample's find the board in all 13 photographs.
TEST(CalibratePhotos, BoardFoundInAllThirteen) {
  EXPECT_EQ(ourPhotoViews().size(), 13u);
  EXPECT_EQ(samplePhotoViews().size(), 13u);
}

// With the sample's corners and flags, calibrate (rejection off) reproduces
// the sample's left_intrinsics.yml, and equals cv::calibrateCamera on the same
// corners to 1e-6 (same optimiser, same inputs).
TEST(CalibratePhotos, SampleCornersReproduceOpenCvSample) {
  const std::vector<View>& views = samplePhotoViews();
  ASSERT_EQ(views.size(), 13u);
  CalibOptions options = sampleOptions();
  options.reject_outliers = false;
  const Calibration c = calibrate(views, kPhotoBoard, kPhotoSize, options);
  std::printf(
      "sample corners: fx %.3f fy %.3f cx %.3f cy %.3f k %.5f %.5f %.5f %.5f %.5f rms %.4f\n",
      c.camera_matrix(0, 0), c.camera_matrix(1, 1), c.camera_matrix(0, 2), c.camera_matrix(1, 2),
      c.distortion[0], c.distortion[1], c.distortion[2], c.distortion[3], c.distortion[4],
      c.rms_px);
  // The sample's detector and flags on the same photographs: fx within 0.5 %,
  // cx, cy within 2 px, RMS within 0.05 px of the sample's file (measured:
  // 0.04 %, 0.09 px, 0.02 px, 0.016 px; the corners here are not bit-identical
  // to those the file was made from).
  expectRelative(c.camera_matrix(0, 0), kSampleF, 0.005, "fx vs sample");
  EXPECT_NEAR(c.camera_matrix(0, 2), kSampleCx, 2.0);
  EXPECT_NEAR(c.camera_matrix(1, 2), kSampleCy, 2.0);
  EXPECT_NEAR(c.rms_px, kSampleRms, 0.05);
  EXPECT_DOUBLE_EQ(c.camera_matrix(0, 0), c.camera_matrix(1, 1));  // aspect held at 1

  const Direct d =
      calibrateDirectly(views, kPhotoBoard, kPhotoSize, cv::CALIB_FIX_ASPECT_RATIO, 1.0);
  expectRelative(c.rms_px, d.rms, 1e-6, "rms vs direct");
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const double e = d.camera_matrix.at<double>(i, j);
      EXPECT_NEAR(c.camera_matrix(i, j), e, 1e-6 * std::max(1.0, std::abs(e))) << i << "," << j;
    }
  }
  for (int i = 0; i < 5; ++i)
    expectRelative(c.distortion[i], d.distortion.at<double>(i), 1e-6, "k");
  for (int v = 0; v < 13; ++v)
    expectRelative(c.per_view_rms_px[v], d.per_view.at<double>(v), 1e-6, "per-view rms");
}

// What outlier rejection does with left02, the sample's worst view (1.18 px in
// left_intrinsics.yml): with the sample's corners (11 x 11 cornerSubPix window,
// wider than left02's small squares) it is rejected, alone, with its error;
// the rest calibrate to a lower RMS.
TEST(CalibratePhotos, SampleCornersRejectLeft02) {
  const std::vector<View>& views = samplePhotoViews();
  ASSERT_EQ(views.size(), 13u);
  const Calibration c = calibrate(views, kPhotoBoard, kPhotoSize, sampleOptions());
  std::printf("sample corners with rejection: threshold %.3f, rejected:", c.outlier_threshold_px);
  for (const RejectedView& r : c.rejected)
    std::printf(" %s (%.3f px)", views[r.view].name.c_str(), r.rms_px);
  std::printf("; rms %.4f -> %.4f, fx %.3f cx %.3f cy %.3f\n", c.first_rms_px, c.rms_px,
              c.camera_matrix(0, 0), c.camera_matrix(0, 2), c.camera_matrix(1, 2));
  ASSERT_EQ(c.rejected.size(), 1u);
  EXPECT_EQ(views[c.rejected[0].view].name, "left02");
  EXPECT_NEAR(c.rejected[0].rms_px, 1.18, 0.1);  // the sample's figure for left02
  EXPECT_EQ(c.views_used.size(), 12u);
  EXPECT_LT(c.rms_px, c.first_rms_px);
}

// Our detector's corners on the same photographs: no view is rejected (left02
// is an ordinary view once its corners are found well), the RMS is well below
// the sample's, and the result agrees with the sample's within the difference
// its corners explain; calibrate equals cv::calibrateCamera on these corners.
TEST(CalibratePhotos, OurCornersCalibrate) {
  const std::vector<View>& views = ourPhotoViews();
  ASSERT_EQ(views.size(), 13u);
  const Calibration c = calibrate(views, kPhotoBoard, kPhotoSize, sampleOptions());
  ASSERT_TRUE(c.std_devs.has_value());
  ASSERT_FALSE(c.worst_corners.empty());
  std::printf(
      "our corners: fx %.3f (sd %.3f) cx %.3f (%.3f) cy %.3f (%.3f) k %.5f %.5f %.5f %.5f %.5f rms "
      "%.4f\n",
      c.camera_matrix(0, 0), c.std_devs->fx_px, c.camera_matrix(0, 2), c.std_devs->cx_px,
      c.camera_matrix(1, 2), c.std_devs->cy_px, c.distortion[0], c.distortion[1], c.distortion[2],
      c.distortion[3], c.distortion[4], c.rms_px);
  std::printf("  per view:");
  for (std::size_t j = 0; j < c.views_used.size(); ++j)
    std::printf(" %s %.3f", views[c.views_used[j]].name.c_str(), c.per_view_rms_px[j]);
  std::printf(
      "\n  threshold %.3f, held-out %.4f (training %.4f, %d folds), worst corner %.3f px (%s "
      "#%d)\n",
      c.outlier_threshold_px, c.held_out.mean_rms_px, c.held_out.mean_training_rms_px,
      c.held_out.folds, c.worst_corners[0].residual_px, views[c.worst_corners[0].view].name.c_str(),
      c.worst_corners[0].corner);
  EXPECT_TRUE(c.rejected.empty());
  EXPECT_EQ(c.views_used.size(), 13u);
  EXPECT_LT(c.rms_px, 0.25);  // the sample's 0.39 px comes from its 11 x 11 window
  // fx within 1 %, cy within 3 px, not 0.5 % and 2 px as above: the sample's
  // corners on left02 are 1.2 px off (its 11 x 11 window is too wide for
  // left02's small squares: with a 5 x 5 window the same detector puts left02
  // at 0.17 px, measured) and pull its fx and cy; with the sample's detector
  // replaced, fx moves by 0.54 % and cy by 1.6 px (measured), several of our
  // standard deviations; the sample's own corners without left02 move the same
  // way (fx 536.1 -> 534.1, cy 235.6 -> 233.7 px; SampleCornersRejectLeft02),
  // so the difference is the sample's corners, not ours.
  expectRelative(c.camera_matrix(0, 0), kSampleF, 0.01, "fx vs sample");
  EXPECT_NEAR(c.camera_matrix(0, 2), kSampleCx, 2.0);
  EXPECT_NEAR(c.camera_matrix(1, 2), kSampleCy, 3.0);

  const Direct d =
      calibrateDirectly(views, kPhotoBoard, kPhotoSize, cv::CALIB_FIX_ASPECT_RATIO, 1.0);
  expectRelative(c.rms_px, d.rms, 1e-6, "rms vs direct");
  expectRelative(c.camera_matrix(1, 1), d.camera_matrix.at<double>(1, 1), 1e-6, "fy vs direct");
  expectRelative(c.camera_matrix(0, 2), d.camera_matrix.at<double>(0, 2), 1e-6, "cx vs direct");
  expectRelative(c.camera_matrix(1, 2), d.camera_matrix.at<double>(1, 2), 1e-6, "cy vs direct");
  for (int i = 0; i < 5; ++i)
    expectRelative(c.distortion[i], d.distortion.at<double>(i), 1e-6, "k");
}

// ---- Synthetic camera ---------------------------------------------------------

struct SyntheticSet {
  test::SyntheticCamera camera;
  std::vector<test::BoardPose> poses;
  std::vector<View> views;                      // detected, canonical order
  std::vector<std::vector<cv::Point2f>> truth;  // true corners in the detections' order
};

const test::SyntheticBoard kSynBoard{};
const BoardSpec kSynSpec{.inner_cols = 9, .inner_rows = 6, .square_m = 0.03};

// The 20 covering views rendered through the lens (black 40, white 210 counts,
// Gaussian noise of 2 counts, seed 1000 + view) and detected by detectBoard.
SyntheticSet buildSet(const test::SyntheticLens& lens) {
  SyntheticSet set{test::SyntheticCamera(lens, kSynBoard), {}, {}, {}};
  const std::vector<test::ViewSpec> specs = test::coveringViewSpecs();
  for (std::size_t i = 0; i < specs.size(); ++i) {
    const test::BoardPose pose = test::poseOf(lens, kSynBoard, specs[i]);
    const cv::Mat image = set.camera.render(pose, 2.0, 1000 + i);
    const std::optional<Detection> d = detectBoard(image, kSynSpec);
    if (!d) continue;
    std::vector<cv::Point2f> truth = set.camera.trueCorners(pose);
    // The detection may be the board turned half round (canonical order).
    if (cv::norm(truth.front() - d->corners_px.front()) >
        cv::norm(truth.back() - d->corners_px.front()))
      std::reverse(truth.begin(), truth.end());
    set.poses.push_back(pose);
    set.views.push_back({d->corners_px, "synthetic" + std::to_string(i)});
    set.truth.push_back(truth);
  }
  return set;
}

const SyntheticSet& radtanSet() {
  static const SyntheticSet set = buildSet(test::SyntheticLens{});
  return set;
}

const test::SyntheticLens kTrue{};

// Every view is found, and its corners lie where the lens puts the board's
// corners: RMS under 0.1 px, none farther than 0.4 px.
TEST(CalibrateSynthetic, CornersMatchTruth) {
  const SyntheticSet& set = radtanSet();
  ASSERT_EQ(set.views.size(), 20u);
  double sum = 0.0, worst = 0.0;
  int n = 0;
  for (std::size_t v = 0; v < set.views.size(); ++v) {
    for (std::size_t i = 0; i < set.truth[v].size(); ++i) {
      const double e = cv::norm(set.views[v].corners_px[i] - set.truth[v][i]);
      sum += e * e;
      worst = std::max(worst, e);
      ++n;
    }
  }
  std::printf("synthetic corners: rms %.4f px, worst %.4f px\n", std::sqrt(sum / n), worst);
  EXPECT_LT(std::sqrt(sum / n), 0.1);
  EXPECT_LT(worst, 0.4);
}

// The known lens is recovered (fx, fy within 0.2 %, cx, cy within 1 px, k1
// within 0.01, RMS <= 0.2 px) and every reported standard deviation covers
// the true error: |error| < 3 sigma.
TEST(CalibrateSynthetic, RecoversKnownLensWithHonestSigmas) {
  const SyntheticSet& set = radtanSet();
  ASSERT_EQ(set.views.size(), 20u);
  const Calibration c = calibrate(set.views, kSynSpec, kTrue.imageSize());
  ASSERT_TRUE(c.std_devs.has_value());
  const IntrinsicStdDevs& s = *c.std_devs;
  const double fx = c.camera_matrix(0, 0), fy = c.camera_matrix(1, 1);
  const double cx = c.camera_matrix(0, 2), cy = c.camera_matrix(1, 2);
  std::printf("synthetic radtan: rms %.4f rejected %zu\n", c.rms_px, c.rejected.size());
  std::printf("  fx %+.4f (sd %.4f)  fy %+.4f (%.4f)  cx %+.4f (%.4f)  cy %+.4f (%.4f)\n",
              fx - kTrue.fx, s.fx_px, fy - kTrue.fy, s.fy_px, cx - kTrue.cx, s.cx_px, cy - kTrue.cy,
              s.cy_px);
  for (int i = 0; i < 5; ++i)
    std::printf("  d%d %+.6f (sd %.6f)\n", i, c.distortion[i] - kTrue.distortion[i],
                s.distortion[i]);
  std::printf("  held-out %.4f (training %.4f)\n", c.held_out.mean_rms_px,
              c.held_out.mean_training_rms_px);
  EXPECT_TRUE(c.rejected.empty());
  EXPECT_LE(c.rms_px, 0.2);
  EXPECT_NEAR(fx, kTrue.fx, 0.002 * kTrue.fx);
  EXPECT_NEAR(fy, kTrue.fy, 0.002 * kTrue.fy);
  EXPECT_NEAR(cx, kTrue.cx, 1.0);
  EXPECT_NEAR(cy, kTrue.cy, 1.0);
  EXPECT_NEAR(c.distortion[0], kTrue.distortion[0], 0.01);
  EXPECT_LT(std::abs(fx - kTrue.fx), 3 * s.fx_px);
  EXPECT_LT(std::abs(fy - kTrue.fy), 3 * s.fy_px);
  EXPECT_LT(std::abs(cx - kTrue.cx), 3 * s.cx_px);
  EXPECT_LT(std::abs(cy - kTrue.cy), 3 * s.cy_px);
  for (int i = 0; i < 5; ++i)
    EXPECT_LT(std::abs(c.distortion[i] - kTrue.distortion[i]), 3 * s.distortion[i])
        << "coefficient " << i;
}

// Few views overfit, and the held-out error shows it: over the 20 windows of
// 3 consecutive views of the set (3 folds, each calibrated on 2 views), the
// median held-out RMS is well above both its training RMS and the held-out
// RMS of all 20 views. With 4 views it is only slightly above (measured
// 1.12 x): the held-out view's pose is solved freely and absorbs much of a
// wrong focal length (a planar board's distance trades against fx), so the
// figure flags views that do not predict each other, not every error.
TEST(CalibrateSynthetic, HeldOutErrorShowsTooFewViews) {
  const SyntheticSet& set = radtanSet();
  ASSERT_EQ(set.views.size(), 20u);
  const Calibration all = calibrate(set.views, kSynSpec, kTrue.imageSize());
  EXPECT_EQ(all.held_out.folds, 5);
  EXPECT_LT(all.held_out.mean_rms_px, 1.1 * all.held_out.mean_training_rms_px);
  auto medianOf = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  };
  std::array<double, 6> medians{};  // held-out and held-out / training, for 3, 4 views
  for (int n : {3, 4}) {
    std::vector<double> held_out, ratio;
    for (int first = 0; first < 20; ++first) {
      std::vector<View> few;
      for (int i = 0; i < n; ++i) few.push_back(set.views[(first + i) % 20]);
      const Calibration c = calibrate(few, kSynSpec, kTrue.imageSize());
      EXPECT_EQ(c.held_out.folds, n);
      held_out.push_back(c.held_out.mean_rms_px);
      ratio.push_back(c.held_out.mean_rms_px / c.held_out.mean_training_rms_px);
    }
    medians[2 * (n - 3)] = medianOf(held_out);
    medians[2 * (n - 3) + 1] = medianOf(ratio);
  }
  std::printf(
      "held-out: 20 views %.4f (training %.4f); median of 3-view windows %.4f "
      "(x%.2f training), 4-view windows %.4f (x%.2f training)\n",
      all.held_out.mean_rms_px, all.held_out.mean_training_rms_px, medians[0], medians[1],
      medians[2], medians[3]);
  EXPECT_GT(medians[0], 1.5 * all.held_out.mean_rms_px);
  EXPECT_GT(medians[1], 1.3);
  EXPECT_GT(medians[2], 1.05 * all.held_out.mean_rms_px);
}

// The fisheye model on the same images: it converges with a small RMS, and
// its undistortion of pixels over the image matches the true (radtan) lens
// within a tolerance set by what the equidistant model cannot represent.
TEST(CalibrateSynthetic, FisheyeModelApproximatesTheLens) {
  const SyntheticSet& set = radtanSet();
  ASSERT_EQ(set.views.size(), 20u);
  CalibOptions options;
  options.model = LensModel::kFisheye;
  const Calibration c = calibrate(set.views, kSynSpec, kTrue.imageSize(), options);
  ASSERT_EQ(c.distortion.size(), 4u);
  ASSERT_TRUE(c.std_devs.has_value());
  std::printf(
      "fisheye: rms %.4f fx %.3f (sd %.3f) fy %.3f cx %.3f (%.3f) cy %.3f k %.5f %.5f %.5f %.5f "
      "held-out %.4f\n",
      c.rms_px, c.camera_matrix(0, 0), c.std_devs->fx_px, c.camera_matrix(1, 1),
      c.camera_matrix(0, 2), c.std_devs->cx_px, c.camera_matrix(1, 2), c.distortion[0],
      c.distortion[1], c.distortion[2], c.distortion[3], c.held_out.mean_rms_px);
  EXPECT_LT(c.rms_px, 0.3);
  std::vector<cv::Point2d> pixels;
  for (double v : {10.0, 120.0, 240.0, 360.0, 470.0})
    for (double u : {10.0, 160.0, 320.0, 480.0, 630.0}) pixels.emplace_back(u, v);
  const std::vector<cv::Point2d> normalised = undistortToNormalised(c, pixels);
  double worst_px = 0.0;
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    const cv::Vec2d truth = kTrue.undistortPixel(pixels[i].x, pixels[i].y);
    worst_px = std::max(
        worst_px, kTrue.fx * std::hypot(normalised[i].x - truth[0], normalised[i].y - truth[1]));
  }
  std::printf("fisheye undistortion vs true lens: worst %.3f px (at the focal length)\n", worst_px);
  EXPECT_LT(worst_px, 2.0);
}

// Exact projections of the board at the poses through the lens, plus Gaussian
// noise of sigma_px per axis: views without rendering or detection.
std::vector<View> projectedViews(const test::SyntheticLens& lens,
                                 const std::vector<test::BoardPose>& poses, double sigma_px,
                                 cv::RNG& rng) {
  const std::vector<cv::Point3f> points = boardObjectPoints(kSynSpec);
  std::vector<View> views;
  for (const test::BoardPose& pose : poses) {
    cv::Matx33d R;
    cv::Rodrigues(pose.rvec, R);
    View v;
    for (const cv::Point3f& p : points) {
      const cv::Point2d uv = lens.project(R * cv::Vec3d(p.x, p.y, p.z) + pose.tvec);
      v.corners_px.emplace_back(static_cast<float>(uv.x + rng.gaussian(sigma_px)),
                                static_cast<float>(uv.y + rng.gaussian(sigma_px)));
    }
    views.push_back(v);
  }
  return views;
}

// ---- Standard deviations ---------------------------------------------------

// The covariance behind the fisheye sigmas, applied to a radtan solve, gives
// OpenCV's stdDeviationsIntrinsics rescaled from (corners - P) to
// (2 corners - P) as covariance.h says: the Jacobian route is OpenCV's.
TEST(CalibrateSigmas, CovarianceMatchesOpenCv) {
  cv::RNG rng(7);
  const std::vector<View> views_px =
      projectedViews(kTrue, test::coveringPoses(kTrue, kSynBoard), 0.1, rng);
  const Direct d = calibrateDirectly(views_px, kSynSpec, kTrue.imageSize(), 0, 1.0);
  // Poses again at the solution (calibrateDirectly does not keep them).
  std::vector<ViewJacobian> views;
  const std::vector<cv::Point3f> points = boardObjectPoints(kSynSpec);
  std::vector<cv::Point3d> points_d(points.begin(), points.end());
  int corners = 0;
  for (const View& v : views_px) {
    cv::Vec3d rvec, tvec;
    ASSERT_TRUE(cv::solvePnP(points, v.corners_px, d.camera_matrix, d.distortion, rvec, tvec));
    std::vector<cv::Point2d> projected;
    cv::Mat j;
    cv::projectPoints(points_d, rvec, tvec, d.camera_matrix, d.distortion, projected, j);
    ViewJacobian vj;
    const int n = static_cast<int>(points.size());
    vj.residuals_px.resize(2 * n);
    vj.d_intrinsics.resize(2 * n, 9);
    vj.d_pose.resize(2 * n, 6);
    for (int i = 0; i < n; ++i) {
      vj.residuals_px(2 * i) = projected[i].x - v.corners_px[i].x;
      vj.residuals_px(2 * i + 1) = projected[i].y - v.corners_px[i].y;
    }
    // projectPoints' columns: rvec, tvec, fx fy, cx cy, k1 k2 p1 p2 k3.
    for (int r = 0; r < 2 * n; ++r) {
      for (int c = 0; c < 6; ++c) vj.d_pose(r, c) = j.at<double>(r, c);
      for (int c = 0; c < 9; ++c) vj.d_intrinsics(r, c) = j.at<double>(r, 6 + c);
    }
    views.push_back(vj);
    corners += n;
  }
  const IntrinsicCovariance cov = intrinsicCovariance(views);
  ASSERT_TRUE(cov.ok);
  const int p = 9 + 6 * static_cast<int>(views_px.size());
  const double rescale = std::sqrt(double(corners - p) / double(2 * corners - p));
  for (int i = 0; i < 9; ++i) {
    expectRelative(std::sqrt(cov.covariance(i, i)), rescale * d.std_intrinsics.at<double>(i), 0.01,
                   "sigma");
  }
}

// Fisheye sigmas by Monte Carlo: exact fisheye projections of 10 poses plus
// Gaussian noise (0.1 px per axis); over 30 noise draws the spread of each
// estimate agrees with the mean reported sigma within 35 % (30 draws estimate a
// spread to about 13 %).
TEST(CalibrateSigmas, FisheyeSigmasMatchMonteCarlo) {
  test::SyntheticLens lens;
  lens.fisheye = true;
  lens.distortion = {0.05, -0.02, 0.01, -0.005};
  // Every other view of the covering set: ten keep the test quick (a fisheye
  // solve takes about 0.1 s per ten views).
  std::vector<test::BoardPose> poses;
  const std::vector<test::BoardPose> all = test::coveringPoses(lens, kSynBoard);
  for (std::size_t i = 0; i < all.size(); i += 2) poses.push_back(all[i]);
  CalibOptions options;
  options.model = LensModel::kFisheye;
  options.max_folds = 0;
  options.reject_outliers = false;
  constexpr int kDraws = 30;
  std::vector<std::array<double, 8>> estimates;
  std::array<double, 8> sigma_sum{};
  cv::RNG rng(42);
  for (int draw = 0; draw < kDraws; ++draw) {
    const std::vector<View> views = projectedViews(lens, poses, 0.1, rng);
    const Calibration c = calibrate(views, kSynSpec, lens.imageSize(), options);
    ASSERT_TRUE(c.std_devs.has_value());
    estimates.push_back({c.camera_matrix(0, 0), c.camera_matrix(1, 1), c.camera_matrix(0, 2),
                         c.camera_matrix(1, 2), c.distortion[0], c.distortion[1], c.distortion[2],
                         c.distortion[3]});
    const IntrinsicStdDevs& s = *c.std_devs;
    const std::array<double, 8> sig = {s.fx_px,         s.fy_px,         s.cx_px,
                                       s.cy_px,         s.distortion[0], s.distortion[1],
                                       s.distortion[2], s.distortion[3]};
    for (int i = 0; i < 8; ++i) sigma_sum[i] += sig[i];
  }
  const char* names[] = {"fx", "fy", "cx", "cy", "k1", "k2", "k3", "k4"};
  for (int i = 0; i < 8; ++i) {
    double mean = 0.0;
    for (const auto& e : estimates) mean += e[i] / kDraws;
    double var = 0.0;
    for (const auto& e : estimates) var += (e[i] - mean) * (e[i] - mean) / (kDraws - 1);
    const double spread = std::sqrt(var), reported = sigma_sum[i] / kDraws;
    std::printf("fisheye sigma %s: reported %.3g, Monte Carlo %.3g (ratio %.2f)\n", names[i],
                reported, spread, reported / spread);
    EXPECT_NEAR(reported / spread, 1.0, 0.35) << names[i];
  }
}

// ---- Bad input ---------------------------------------------------------------

// Fewer than 3 views, a view with the wrong number of corners, radtan options
// with the fisheye model and an empty image size are refused with messages
// that say so.
TEST(CalibrateInput, BadInputIsRefused) {
  cv::RNG rng(11);
  const std::vector<View> views =
      projectedViews(kTrue, test::coveringPoses(kTrue, kSynBoard), 0.1, rng);
  const std::vector<View> two(views.begin(), views.begin() + 2);
  try {
    calibrate(two, kSynSpec, kTrue.imageSize());
    FAIL() << "two views accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("at least 3"), std::string::npos) << e.what();
  }
  std::vector<View> short_view(views.begin(), views.begin() + 3);
  short_view[1].corners_px.pop_back();
  try {
    calibrate(short_view, kSynSpec, kTrue.imageSize());
    FAIL() << "a view with 53 corners accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("view 1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("53 corners"), std::string::npos) << e.what();
  }
  CalibOptions fisheye;
  fisheye.model = LensModel::kFisheye;
  fisheye.fix_k3 = true;
  EXPECT_THROW(calibrate(views, kSynSpec, kTrue.imageSize(), fisheye), std::invalid_argument);
  EXPECT_THROW(calibrate(views, kSynSpec, cv::Size(0, 480)), std::invalid_argument);
}

}  // namespace
}  // namespace nadir::calib
