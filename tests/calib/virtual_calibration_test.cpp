// The calibration targets on the virtual camera: views of the rendered
// checkerboard taken automatically (a view kept only when it adds coverage),
// calibrated, and compared with the lens the renderer used (the truth, set in
// scenarios/calibration.yaml: 1280 x 960, 84.872 deg, k1 = -0.20, k2 = 0.05,
// sensor noise on).

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <opencv2/calib3d.hpp>

#include "calib/session.h"
#include "calib/sources/frame_sources.h"

namespace nadir::calib {
namespace {

struct Result {
  Calibration calibration;
  render::CameraIntrinsics truth;
  int views = 0;
  // Farthest any detected corner lies from the image centre, px.
  double max_corner_radius_px = 0.0;
};

Result calibrateVirtual(const std::vector<std::string>& overrides, LensModel model, int max_views) {
  const std::unique_ptr<FrameSource> source = openVirtualSource("calibration", overrides);
  CalibrationSession session(*source->board());
  while (const std::optional<SourceFrame> image = source->next()) {
    session.offer(image->gray, image->name, true);
    if (static_cast<int>(session.views().size()) >= max_views) break;
  }
  CalibOptions options;
  options.model = model;
  Result result{session.calibrate(options), *source->trueLens(),
                static_cast<int>(session.views().size())};
  const cv::Point2d centre(0.5 * (result.truth.width - 1), 0.5 * (result.truth.height - 1));
  for (const View& view : session.views()) {
    for (const cv::Point2f& corner : view.corners_px) {
      result.max_corner_radius_px =
          std::max(result.max_corner_radius_px, cv::norm(cv::Point2d(corner) - centre));
    }
  }
  return result;
}

// From 25 automatic views: fx and fy within 0.2 %, cx and cy within 1 px, k1
// within 0.01, RMS <= 0.2 px, and every intrinsic within 3 of its reported
// standard deviations of the truth.
TEST(VirtualCalibration, RadtanLensFrom25AutomaticViews) {
  const Result r = calibrateVirtual({}, LensModel::kRadtan, 25);
  ASSERT_EQ(r.views, 25);
  const Calibration& c = r.calibration;
  const render::CameraIntrinsics& t = r.truth;
  // The lens scenarios/calibration.yaml sets, worked out by hand: fx = 640 / tan(42.436 deg).
  EXPECT_NEAR(t.fx, 640.0 / std::tan(84.872 / 2 * M_PI / 180), 1e-9);
  EXPECT_DOUBLE_EQ(t.distortion[0], -0.20);
  EXPECT_DOUBLE_EQ(t.distortion[1], 0.05);
  const cv::Matx33d& K = c.camera_matrix;
  EXPECT_NEAR(K(0, 0) / t.fx, 1.0, 0.002);
  EXPECT_NEAR(K(1, 1) / t.fy, 1.0, 0.002);
  EXPECT_NEAR(K(0, 2), t.cx, 1.0);
  EXPECT_NEAR(K(1, 2), t.cy, 1.0);
  EXPECT_NEAR(c.distortion[0], t.distortion[0], 0.01);
  EXPECT_LE(c.rms_px, 0.2);
  ASSERT_TRUE(c.std_devs.has_value());
  const IntrinsicStdDevs& sd = *c.std_devs;
  EXPECT_LT(std::abs(K(0, 0) - t.fx), 3 * sd.fx_px);
  EXPECT_LT(std::abs(K(1, 1) - t.fy), 3 * sd.fy_px);
  EXPECT_LT(std::abs(K(0, 2) - t.cx), 3 * sd.cx_px);
  EXPECT_LT(std::abs(K(1, 2) - t.cy), 3 * sd.cy_px);
  for (int i = 0; i < 5; ++i)
    EXPECT_LT(std::abs(c.distortion[i] - t.distortion[i]), 3 * sd.distortion[i])
        << "coefficient " << i;
}

// The same camera at 640 x 480 calibrated with the fisheye model: the
// fisheye's coefficients are not the lens's, but its pinhole part is (both
// models are the identity near the axis), and it maps rays to the same pixels
// as the true lens wherever the views had corners (beyond them, in the
// image's corners, the two models part by up to 6 px).
TEST(VirtualCalibration, FisheyeModelAt640x480) {
  const Result r =
      calibrateVirtual({"camera.width=640", "camera.height=480"}, LensModel::kFisheye, 25);
  ASSERT_EQ(r.views, 25);
  const Calibration& c = r.calibration;
  const render::CameraIntrinsics& t = r.truth;
  EXPECT_EQ(t.width, 640);
  const cv::Matx33d& K = c.camera_matrix;
  EXPECT_NEAR(K(0, 0) / t.fx, 1.0, 0.002);
  EXPECT_NEAR(K(1, 1) / t.fy, 1.0, 0.002);
  EXPECT_NEAR(K(0, 2), t.cx, 1.0);
  EXPECT_NEAR(K(1, 2), t.cy, 1.0);
  EXPECT_LE(c.rms_px, 0.2);
  // Rays through a grid over the true image, as far out as the corners went,
  // projected by both lenses.
  std::vector<cv::Point3d> rays;
  std::vector<Eigen::Vector2d> true_pixels;
  EXPECT_GT(r.max_corner_radius_px, 0.75 * std::hypot(t.width / 2.0, t.height / 2.0));
  for (int v = 0; v < t.height; v += 16) {
    for (int u = 0; u < t.width; u += 16) {
      if (std::hypot(u - t.cx, v - t.cy) > r.max_corner_radius_px) continue;
      const std::optional<Eigen::Vector2d> xy = t.undistortPixel({double(u), double(v)});
      ASSERT_TRUE(xy.has_value());
      rays.emplace_back(xy->x(), xy->y(), 1.0);
      true_pixels.emplace_back(u, v);
    }
  }
  std::vector<cv::Point2d> fisheye_pixels;
  cv::fisheye::projectPoints(rays, fisheye_pixels, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K,
                             c.distortion);
  double worst_px = 0.0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    worst_px = std::max(worst_px, std::hypot(fisheye_pixels[i].x - true_pixels[i].x(),
                                             fisheye_pixels[i].y - true_pixels[i].y()));
  }
  EXPECT_LT(worst_px, 0.5);
}

}  // namespace
}  // namespace nadir::calib
