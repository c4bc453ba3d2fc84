// The virtual checkerboard against geometry worked out independently: every
// pose holds the whole board, the poses spread over the image, and the
// corners a detector finds in the rendered images sit where the lens model
// (cv::projectPoints) puts the board's known corners.

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <vector>

#include <opencv2/calib3d.hpp>

#include "calib/virtual/virtual_board.h"

namespace nadir::calib {
namespace {

// The calibration target's virtual camera: 1280 x 960, 84.9 deg, k1 = -0.20, k2 = 0.05.
render::CameraParams issueCamera() {
  render::CameraParams camera;
  camera.width = 1280;
  camera.height = 960;
  camera.hfov_deg = 84.9;
  camera.distortion = {-0.20, 0.05, 0.0, 0.0, 0.0};
  return camera;
}

std::vector<cv::Point2d> projectCorners(const std::vector<Eigen::Vector3d>& corners_world,
                                        const Eigen::Isometry3d& T_world_cam,
                                        const render::CameraIntrinsics& k) {
  std::vector<cv::Point2d> pixels;
  const Eigen::Isometry3d T_cam_world = T_world_cam.inverse();
  std::vector<cv::Point3d> points_cam;
  for (const Eigen::Vector3d& p : corners_world) {
    const Eigen::Vector3d p_cam = T_cam_world * p;
    points_cam.emplace_back(p_cam.x(), p_cam.y(), p_cam.z());
  }
  const cv::Matx33d camera_matrix(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  const std::vector<double> distortion(k.distortion.begin(), k.distortion.end());
  cv::projectPoints(points_cam, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), camera_matrix, distortion,
                    pixels);
  return pixels;
}

// Every pose keeps the board's corners inside the image, and the board's
// centre visits all nine cells of a 3 x 3 grid over the image.
TEST(VirtualBoard, PosesHoldTheBoardAndCoverTheImage) {
  const terrain::CheckerboardParams board{.inner_cols = 9, .inner_rows = 6, .square_m = 0.025};
  const render::CameraIntrinsics k = issueCamera().intrinsics();
  const std::vector<Eigen::Isometry3d> poses = coveringPoses(board, k, VirtualViewParams{});
  ASSERT_EQ(poses.size(), 60u);
  const terrain::CheckerboardWorld world(board);
  std::set<int> cells;
  for (const Eigen::Isometry3d& T_world_cam : poses) {
    const std::vector<cv::Point2d> pixels =
        projectCorners(boardCorners_world(world), T_world_cam, k);
    cv::Point2d mean(0, 0);
    for (const cv::Point2d& uv : pixels) {
      EXPECT_GT(uv.x, 0.0);
      EXPECT_GT(uv.y, 0.0);
      EXPECT_LT(uv.x, k.width - 1.0);
      EXPECT_LT(uv.y, k.height - 1.0);
      mean += uv / static_cast<double>(pixels.size());
    }
    cells.insert(static_cast<int>(3 * mean.x / k.width) +
                 3 * static_cast<int>(3 * mean.y / k.height));
  }
  EXPECT_EQ(cells.size(), 9u);
}

// The detector finds the board in rendered views (distortion and sensor
// noise on) within 0.25 px RMS of where cv::projectPoints puts its corners.
// It finds it in 11 of the first 12: view 0 holds the board tilted 38 deg at
// the image's top-left corner, and findChessboardCornersSB gives up there.
TEST(VirtualBoard, RenderedCornersMatchTheLensModel) {
  const terrain::CheckerboardParams board{.inner_cols = 9, .inner_rows = 6, .square_m = 0.025};
  render::CameraParams camera = issueCamera();
  camera.read_noise_counts = 2.0;
  camera.shot_noise_electrons_per_count = 10.0;
  VirtualViewParams views;
  views.views = 12;
  VirtualCheckerboard virtual_board(board, camera, views);
  ASSERT_EQ(virtual_board.size(), 12);
  const std::vector<Eigen::Vector3d> corners_world = boardCorners_world(virtual_board.world());
  int detected = 0;
  for (int i = 0; i < virtual_board.size(); ++i) {
    const render::RenderedImage frame = virtual_board.render(i);
    std::vector<cv::Point2f> found;
    if (!cv::findChessboardCornersSB(frame.image, cv::Size(9, 6), found,
                                     cv::CALIB_CB_ACCURACY | cv::CALIB_CB_NORMALIZE_IMAGE)) {
      continue;
    }
    ++detected;
    const std::vector<cv::Point2d> expected =
        projectCorners(corners_world, virtual_board.poses()[static_cast<std::size_t>(i)],
                       virtual_board.intrinsics());
    double sum_sq = 0.0;
    double worst = 0.0;
    for (const cv::Point2f& f : found) {
      double best = 1e9;
      for (const cv::Point2d& e : expected) best = std::min(best, std::hypot(f.x - e.x, f.y - e.y));
      sum_sq += best * best;
      worst = std::max(worst, best);
    }
    const double rms = std::sqrt(sum_sq / found.size());
    EXPECT_LT(rms, 0.25) << "view " << i;
    EXPECT_LT(worst, 0.6) << "view " << i;
  }
  EXPECT_GE(detected, 11);
}

}  // namespace
}  // namespace nadir::calib
