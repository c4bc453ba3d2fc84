// The camera rig's timing in message time, its mounting geometry and its camera_info_t.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>

#include "calib/calibration_file.h"
#include "nodes/camera/camera_rig.h"
#include "render/egl_context.h"
#include "terrain/checkerboard_world.h"

namespace nadir::camera {
namespace {

// 9 x 7 squares of 1 m: 8 inner corners along north, 6 along east.
const terrain::CheckerboardParams kBoard{.inner_cols = 6, .inner_rows = 8, .square_m = 1.0};

struct Rig {
  render::HeadlessGlContext context;
  std::shared_ptr<terrain::TileTree> tiles;
  std::unique_ptr<render::TerrainRenderer> terrain;
  std::unique_ptr<CameraRig> rig;

  explicit Rig(const std::map<std::string, CameraSpec>& specs) {
    auto world = std::make_shared<terrain::CheckerboardWorld>(kBoard);
    terrain::TileParams tile_params;
    tile_params.texture_px = 64;
    tiles = std::make_shared<terrain::TileTree>(world, tile_params);
    terrain = std::make_unique<render::TerrainRenderer>(tiles, render::TerrainRendererParams{});
    rig = std::make_unique<CameraRig>(*terrain, specs);
  }
};

CameraSpec smallCamera(double fps) {
  CameraSpec spec;
  spec.camera.width = 64;
  spec.camera.height = 48;
  spec.fps = fps;
  return spec;
}

Eigen::Isometry3d bodyAt(double north) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(north, 0.0, -20.0);
  return T;
}

// At 200 Hz poses, a 31 Hz and a 100 Hz camera render 31 and 100 frames in a second,
// each stamped with the pose that triggered it, on a fixed grid of due times.
TEST(CameraRig, FramesFollowMessageTime) {
  Rig rig({{"vo", smallCamera(31.0)}, {"ppa", smallCamera(100.0)}});
  std::map<std::string, std::vector<std::int64_t>> stamps;
  for (int i = 0; i < 200; ++i) {
    const std::int64_t utime = 5'000'000 + i * 5'000;
    for (const CameraFrame& frame : rig.rig->onPose(utime, bodyAt(0.01 * i))) {
      EXPECT_EQ(frame.rendered.utime, utime);
      stamps[frame.name].push_back(utime);
    }
  }
  EXPECT_EQ(stamps["ppa"].size(), 100u);
  // 31 Hz: due every 32258 us from 5.0 s; poses every 5 ms, so each frame comes
  // at the first pose at or after 5'000'000 + k * 32258.
  ASSERT_EQ(stamps["vo"].size(), 31u);
  for (std::size_t k = 0; k < stamps["vo"].size(); ++k) {
    const std::int64_t due = 5'000'000 + static_cast<std::int64_t>(k) * 32258;
    const std::int64_t expected = 5'000'000 + (due - 5'000'000 + 4'999) / 5'000 * 5'000;
    EXPECT_EQ(stamps["vo"][k], expected) << "frame " << k;
  }
}

// With a rolling shutter (30 ms readout), a frame waits for the pose 15 ms after
// its time, keeps its time as its stamp, and is rendered with the camera's
// motion between the poses 15 ms either side: here a roll of 45 deg/s about
// the nose (the camera's -y axis) while flying north at 25 m/s (its -y).
TEST(CameraRig, RollingShutterFramesWaitForTheirReadoutAndCarryTheMotion) {
  CameraSpec spec = smallCamera(10.0);
  spec.camera.width = 320;
  spec.camera.height = 240;
  spec.camera.rolling_shutter = true;
  spec.camera.readout_s = 0.03;
  Rig rig({{"vo", spec}});
  constexpr double kRate = 45.0 * M_PI / 180.0;
  const auto pose = [&](std::int64_t utime) {
    const double t = static_cast<double>(utime - 1'000'000) * 1e-6;
    Eigen::Isometry3d T = bodyAt(25.0 * t);
    T.linear() = Eigen::AngleAxisd(kRate * t, Eigen::Vector3d::UnitX()).toRotationMatrix();
    return T;
  };
  std::vector<CameraFrame> frames;
  std::vector<std::int64_t> arrived_at;
  for (std::int64_t utime = 1'000'000; utime <= 1'020'000; utime += 2'500) {
    for (CameraFrame& frame : rig.rig->onPose(utime, pose(utime))) {
      frames.push_back(std::move(frame));
      arrived_at.push_back(utime);
    }
  }
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].rendered.utime, 1'000'000);
  EXPECT_EQ(arrived_at[0], 1'015'000);

  // The same frame from a renderer given the motion by hand. The rig's first
  // frame has no pose before it, so its motion spans 0 to +15 ms: the same rates.
  render::CameraMotion motion;
  motion.omega_cam_rps = Eigen::Vector3d(0.0, -kRate, 0.0);
  motion.v_cam_mps = Eigen::Vector3d(0.0, -25.0, 0.0);
  render::CameraRenderer renderer(*rig.terrain, spec.camera);
  const cv::Mat expected =
      renderer.render(pose(1'000'000) * spec.T_body_cam(), 1'000'000, false, motion).image;
  EXPECT_LE(cv::norm(frames[0].rendered.image, expected, cv::NORM_INF), 1.0);
  const cv::Mat still = renderer.render(pose(1'000'000) * spec.T_body_cam(), 1'000'000).image;
  EXPECT_GT(cv::norm(frames[0].rendered.image, still, cv::NORM_INF), 20.0)
      << "the motion should show in the image";
}

// Stamps carry the camera's clock offset and a Gaussian jitter: over 400
// frames, stamp - true time - offset has a mean within 3 sigma / sqrt(400) of
// zero and a standard deviation within 10 % of sigma, never beyond 3 sigma;
// the same frame gets the same stamp every time; camera_info_t says so.
TEST(CameraRig, StampsCarryTheClockOffsetAndTheJitter) {
  CameraSpec spec = smallCamera(100.0);
  spec.time_offset_s = 0.004;
  spec.timestamp_jitter_s = 0.0005;
  double sum = 0.0, sum2 = 0.0, largest = 0.0;
  for (int i = 0; i < 400; ++i) {
    const std::int64_t true_utime = 2'000'000 + i * 10'000;
    const double jitter_s =
        static_cast<double>(spec.stampOf(true_utime) - true_utime) * 1e-6 - 0.004;
    EXPECT_EQ(spec.stampOf(true_utime), spec.stampOf(true_utime));
    sum += jitter_s;
    sum2 += jitter_s * jitter_s;
    largest = std::max(largest, std::abs(jitter_s));
  }
  const double mean = sum / 400.0;
  const double sigma = std::sqrt(sum2 / 400.0 - mean * mean);
  EXPECT_LT(std::abs(mean), 3.0 * 0.0005 / 20.0);
  EXPECT_NEAR(sigma, 0.0005, 0.00005);
  EXPECT_LE(largest, 3.0 * 0.0005 + 1e-6);

  Rig rig({{"vo", spec}});
  const std::vector<CameraFrame> frames = rig.rig->onPose(5'000'000, bodyAt(0.0));
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].rendered.utime, spec.stampOf(5'000'000));
  EXPECT_NE(frames[0].rendered.utime, 5'000'000);
  const msg::CameraInfo info =
      cameraInfo("vo", spec, rig.rig->intrinsics("vo"), frames[0].rendered.utime);
  EXPECT_EQ(info.time_offset_s, 0.004);
  EXPECT_EQ(info.timestamp_jitter_s, 0.0005);
  EXPECT_EQ(info.readout_s, 0.0);
}

// A jump back in time (a log played again) restarts the frame timing instead of stalling.
TEST(CameraRig, TimeGoingBackwardsRestarts) {
  Rig rig({{"vo", smallCamera(10.0)}});
  EXPECT_EQ(rig.rig->onPose(10'000'000, bodyAt(0)).size(), 1u);
  EXPECT_EQ(rig.rig->onPose(10'050'000, bodyAt(0)).size(), 0u);
  EXPECT_EQ(rig.rig->onPose(1'000'000, bodyAt(0)).size(), 1u);
}

// The camera pose is the body pose times the mount: a forward mount offset moves the
// camera north when the body faces north; a straight-down mount looks along body +z.
TEST(CameraRig, MountGeometry) {
  CameraSpec spec = smallCamera(10.0);
  spec.mount_position_m = {0.5, 0.0, 0.1};
  const Eigen::Isometry3d T_body_cam = spec.T_body_cam();
  EXPECT_NEAR((T_body_cam.rotation().col(2) - Eigen::Vector3d(0, 0, 1)).norm(), 0.0, 1e-15);
  Rig rig({{"vo", spec}});
  const std::vector<CameraFrame> frames = rig.rig->onPose(0, bodyAt(3.0));
  ASSERT_EQ(frames.size(), 1u);
  const Eigen::Vector3d p = frames[0].rendered.T_world_cam.translation();
  EXPECT_NEAR(p.x(), 3.5, 1e-12);
  EXPECT_NEAR(p.z(), -19.9, 1e-12);
  // Mount pitched 90 deg forward from straight down: the optical axis points at the nose.
  spec.mount_rpy_deg = {0.0, 90.0, 0.0};
  EXPECT_NEAR((spec.T_body_cam().rotation().col(2) - Eigen::Vector3d(1, 0, 0)).norm(), 0.0, 1e-12);
}

// camera_info_t carries the intrinsics and the mount (down camera: R_body_cam columns (0,1,0),
// (-1,0,0), (0,0,1)).
TEST(CameraRig, CameraInfoCarriesIntrinsicsAndMount) {
  CameraSpec spec;
  spec.fps = 31.0;
  spec.mount_position_m = {0.2, -0.1, 0.05};
  render::CameraIntrinsics k = render::CameraIntrinsics::fromHorizontalFov(1280, 960, 1.4813);
  k.distortion = {-0.1, 0.01, 0.0, 0.0, 0.0};
  const msg::CameraInfo info = cameraInfo("down", spec, k, 42);
  EXPECT_EQ(info.utime, 42);
  EXPECT_EQ(info.camera_name, "down");
  EXPECT_EQ(info.width, 1280);
  EXPECT_EQ(info.fx, k.fx);
  EXPECT_EQ(info.cx, 639.5);
  EXPECT_EQ(info.distortion_model, msg::Distortion::RADTAN);
  ASSERT_EQ(info.distortion.size(), 5u);
  EXPECT_EQ(info.distortion[0], -0.1);
  EXPECT_EQ(info.fps, 31.0);
  EXPECT_EQ(info.p_cam_in_body_m.x(), 0.2);
  // Rotation of 90 deg about body z: w = cos 45, z = sin 45.
  EXPECT_NEAR(info.q_body_cam.w(), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(info.q_body_cam.z(), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(info.q_body_cam.x(), 0.0, 1e-12);
}

}  // namespace
}  // namespace nadir::camera

namespace nadir::camera {
namespace {

std::string writeLens(const std::string& name, int width, int height, calib::LensModel model) {
  calib::CalibrationFile file;
  file.model = model;
  file.image_width = width;
  file.image_height = height;
  file.camera_matrix = cv::Matx33d(50.5, 0, 31.25, 0, 50.25, 23.75, 0, 0, 1);
  file.distortion = model == calib::LensModel::kFisheye
                        ? std::vector<double>{0.1, 0.01, 0, 0}
                        : std::vector<double>{-0.1, 0.02, 0.001, -0.002, 0.0};
  const std::string path = ::testing::TempDir() + "nadir_rig_" + name + ".yaml";
  calib::writeCalibrationFile(path, file);
  return path;
}

// With a calibration file the rig renders with its true lens but announces
// the file's, as a real camera announces its calibration.
TEST(CameraRig, CalibrationFileIsTheAnnouncedLens) {
  CameraSpec spec = smallCamera(10.0);
  spec.calibration_file = writeLens("good", 64, 48, calib::LensModel::kRadtan);
  Rig rig({{"down", spec}});
  const render::CameraIntrinsics& rendered = rig.rig->intrinsics("down");
  const render::CameraIntrinsics& announced = rig.rig->announcedIntrinsics("down");
  EXPECT_FALSE(rendered.hasDistortion());
  EXPECT_DOUBLE_EQ(announced.fx, 50.5);
  EXPECT_DOUBLE_EQ(announced.fy, 50.25);
  EXPECT_DOUBLE_EQ(announced.cx, 31.25);
  EXPECT_DOUBLE_EQ(announced.cy, 23.75);
  EXPECT_DOUBLE_EQ(announced.distortion[0], -0.1);
  EXPECT_DOUBLE_EQ(announced.distortion[3], -0.002);
  const msg::CameraInfo info = cameraInfo("down", spec, announced, 7);
  EXPECT_DOUBLE_EQ(info.fx, 50.5);
  EXPECT_EQ(info.distortion_model, msg::Distortion::RADTAN);
  // Without a file the announced lens is the rendering one.
  Rig plain({{"down", smallCamera(10.0)}});
  EXPECT_DOUBLE_EQ(plain.rig->announcedIntrinsics("down").fx, plain.rig->intrinsics("down").fx);
}

// A file for another image size, a fisheye file and a missing file are
// refused, naming the camera and the file.
TEST(CameraRig, WrongCalibrationFileIsRefused) {
  auto errorOf = [](const std::string& path) {
    CameraSpec spec = smallCamera(10.0);
    spec.calibration_file = path;
    try {
      Rig rig({{"down", spec}});
    } catch (const std::runtime_error& error) {
      return std::string(error.what());
    }
    return std::string();
  };
  const std::string wrong_size = errorOf(writeLens("big", 640, 480, calib::LensModel::kRadtan));
  EXPECT_NE(wrong_size.find("camera down: calibration_file"), std::string::npos) << wrong_size;
  EXPECT_NE(wrong_size.find("is for 640x480 images, the camera makes 64x48"), std::string::npos)
      << wrong_size;
  const std::string fisheye = errorOf(writeLens("fisheye", 64, 48, calib::LensModel::kFisheye));
  EXPECT_NE(fisheye.find("fisheye"), std::string::npos) << fisheye;
  const std::string missing = errorOf("/nonexistent/lens.yaml");
  EXPECT_NE(missing.find("/nonexistent/lens.yaml"), std::string::npos) << missing;
}

}  // namespace
}  // namespace nadir::camera
