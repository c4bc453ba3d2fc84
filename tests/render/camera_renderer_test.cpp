// The virtual camera against geometry worked out independently: a flat
// checkerboard seen from a known pose lands where the pinhole model (or
// OpenCV's projectPoints, with distortion) puts its corners.

#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include "core/frames.h"
#include "nodes/common/photometric.h"
#include "render/camera_renderer.h"
#include "render/egl_context.h"
#include "terrain/checkerboard_world.h"
#include "terrain/procedural_world.h"

namespace nadir::render {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
// 9 x 7 squares of 1 m: 8 inner corners along north, 6 along east.
const terrain::CheckerboardParams kBoard{.inner_cols = 6, .inner_rows = 8, .square_m = 1.0};

// Camera pose of a body at (north, east, down) with roll/pitch/yaw carrying a down camera.
Eigen::Isometry3d downCameraPose(const Eigen::Vector3d& p_ned, double roll, double pitch,
                                 double yaw) {
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  T_world_cam.linear() =
      core::rotationFromRpy({roll, pitch, yaw}) * core::rotationBodyFromDownCamera();
  T_world_cam.translation() = p_ned;
  return T_world_cam;
}

struct Fixture {
  HeadlessGlContext context;
  std::shared_ptr<terrain::CheckerboardWorld> world;
  std::shared_ptr<terrain::TileTree> tiles;
  std::unique_ptr<TerrainRenderer> terrain;

  explicit Fixture(double ground_up_m = 0.0) {
    world = std::make_shared<terrain::CheckerboardWorld>(kBoard, ground_up_m);
    terrain::TileParams tile_params;
    tile_params.texture_px = 256;
    tiles = std::make_shared<terrain::TileTree>(world, tile_params);
    terrain = std::make_unique<TerrainRenderer>(tiles, TerrainRendererParams{});
  }
};

CameraParams testCamera() {
  CameraParams params;
  params.width = 640;
  params.height = 480;
  params.hfov_deg = 70.0;
  params.ground_detail = false;
  return params;
}

// Largest distance from each detected corner to the nearest expected one, px.
double worstCornerError(const std::vector<cv::Point2f>& detected,
                        const std::vector<cv::Point2d>& expected) {
  double worst = 0.0;
  for (const cv::Point2f& d : detected) {
    double best = 1e9;
    for (const cv::Point2d& e : expected) best = std::min(best, std::hypot(d.x - e.x, d.y - e.y));
    worst = std::max(worst, best);
  }
  return worst;
}

std::vector<Eigen::Vector3d> boardCorners(const terrain::CheckerboardWorld& world,
                                          double ground_up_m) {
  std::vector<Eigen::Vector3d> corners;
  for (int i = 0; i < 8; ++i) {
    for (int j = 0; j < 6; ++j)
      corners.emplace_back(world.cornerNorth_m(i), world.cornerEast_m(j), -ground_up_m);
  }
  return corners;
}

std::vector<cv::Point2f> detectCorners(const cv::Mat& gray) {
  std::vector<cv::Point2f> corners;
  const bool found =
      cv::findChessboardCornersSB(gray, cv::Size(6, 8), corners, cv::CALIB_CB_ACCURACY);
  EXPECT_TRUE(found) << "the checkerboard was not found in the rendered image";
  return corners;
}

// Board corners rendered without distortion sit within 0.5 px of the pinhole projection.
TEST(CameraRenderer, CheckerCornersMatchPinholeProjection) {
  Fixture fixture(3.0);
  CameraRenderer camera(*fixture.terrain, testCamera());
  const Eigen::Isometry3d T_world_cam =
      downCameraPose({0.3, -0.2, -15.0}, 3.0 * kDeg, -2.0 * kDeg, 10.0 * kDeg);
  const RenderedImage frame = camera.render(T_world_cam, 0);
  ASSERT_EQ(frame.image.type(), CV_8UC1);
  ASSERT_EQ(frame.image.cols, 640);

  const CameraIntrinsics& k = camera.intrinsics();
  std::vector<cv::Point2d> expected;
  for (const Eigen::Vector3d& p_world : boardCorners(*fixture.world, 3.0)) {
    const Eigen::Vector3d p_cam = T_world_cam.inverse() * p_world;
    // Pinhole by hand: u = fx x/z + cx, v = fy y/z + cy.
    expected.emplace_back(k.fx * p_cam.x() / p_cam.z() + k.cx, k.fy * p_cam.y() / p_cam.z() + k.cy);
  }
  const std::vector<cv::Point2f> detected = detectCorners(frame.image);
  ASSERT_EQ(detected.size(), 48u);
  EXPECT_LT(worstCornerError(detected, expected), 0.5);
}

// With Brown-Conrady distortion on, corners sit within 0.5 px of cv::projectPoints.
TEST(CameraRenderer, DistortedCornersMatchOpenCvProjectPoints) {
  Fixture fixture;
  CameraParams params = testCamera();
  params.distortion = {-0.28, 0.09, 0.0012, -0.0008, -0.012};
  CameraRenderer camera(*fixture.terrain, params);
  const Eigen::Isometry3d T_world_cam =
      downCameraPose({-0.4, 0.5, -12.0}, -2.0 * kDeg, 4.0 * kDeg, -25.0 * kDeg);
  const RenderedImage frame = camera.render(T_world_cam, 0);

  const CameraIntrinsics& k = camera.intrinsics();
  const Eigen::Isometry3d T_cam_world = T_world_cam.inverse();
  std::vector<cv::Point3d> object_points;
  for (const Eigen::Vector3d& p : boardCorners(*fixture.world, 0.0))
    object_points.emplace_back(p.x(), p.y(), p.z());
  cv::Mat R_cam_world, rvec, tvec;
  cv::eigen2cv(Eigen::Matrix3d(T_cam_world.rotation()), R_cam_world);
  cv::Rodrigues(R_cam_world, rvec);
  cv::eigen2cv(Eigen::Vector3d(T_cam_world.translation()), tvec);
  const cv::Matx33d camera_matrix(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  std::vector<cv::Point2d> expected;
  cv::projectPoints(object_points, rvec, tvec, camera_matrix, params.distortion, expected);

  const std::vector<cv::Point2f> detected = detectCorners(frame.image);
  ASSERT_EQ(detected.size(), 48u);
  EXPECT_LT(worstCornerError(detected, expected), 0.5);
}

// The same pose renders the same bytes, also from a second renderer; noise follows the utime.
TEST(CameraRenderer, RendersAreBitIdentical) {
  CameraParams params = testCamera();
  params.ground_detail = true;
  params.read_noise_counts = 2.0;
  params.shot_noise_electrons_per_count = 4.0;
  const Eigen::Isometry3d T_world_cam = downCameraPose({1.0, 2.0, -8.0}, 0.1, -0.05, 0.3);
  cv::Mat first, second, third;
  {
    Fixture fixture;
    CameraRenderer camera(*fixture.terrain, params);
    first = camera.render(T_world_cam, 1'000'000).image.clone();
    second = camera.render(T_world_cam, 1'000'000).image.clone();
    third = camera.render(T_world_cam, 1'033'333).image.clone();
  }
  Fixture again;
  CameraRenderer camera(*again.terrain, params);
  const cv::Mat fresh = camera.render(T_world_cam, 1'000'000).image;
  EXPECT_EQ(cv::norm(first, second, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(first, fresh, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(first, third, cv::NORM_L1), 0.0) << "noise did not change with the frame time";
}

// Per-pixel depth equals the distance along the optical axis to the flat ground.
TEST(CameraRenderer, DepthIsDistanceAlongOpticalAxis) {
  Fixture fixture(2.0);
  CameraRenderer camera(*fixture.terrain, testCamera());
  const Eigen::Isometry3d T_world_cam = downCameraPose({0.0, 0.0, -20.0}, 10.0 * kDeg, 0.0, 0.0);
  const RenderedImage frame = camera.render(T_world_cam, 0, true);
  ASSERT_EQ(frame.depth_m.type(), CV_32FC1);
  const CameraIntrinsics& k = camera.intrinsics();
  // Ground plane down = -2: along the ray through pixel (u, v), depth z solves
  // (p_cam_world + z R (x, y, 1)).down = -2 with x = (u - cx)/fx, y = (v - cy)/fy.
  const Eigen::Matrix3d R = T_world_cam.rotation();
  for (const auto& [u, v] :
       std::vector<std::pair<int, int>>{{320, 240}, {10, 10}, {600, 450}, {100, 400}}) {
    const Eigen::Vector3d ray = R * Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
    const double z = (-2.0 - T_world_cam.translation().z()) / ray.z();
    EXPECT_NEAR(frame.depth_m.at<float>(v, u), z, 0.01 * z) << "pixel " << u << ", " << v;
  }
}

// The checkerboard world with one flat-roofed building, 4 m x 4 m and 6 m
// tall, centred 5 m north of the origin.
class BuildingWorld : public terrain::CheckerboardWorld {
 public:
  BuildingWorld() : CheckerboardWorld(kBoard) {}
  std::vector<terrain::GroundObject> objects(const terrain::GroundSquare& sq) const override {
    terrain::GroundObject building;
    building.kind = terrain::GroundObject::Kind::kBuilding;
    building.north_m = 5.0;
    building.height_m = 6.0;
    building.half_length_m = building.half_width_m = 2.0;
    building.rgb = {250, 250, 250};
    const bool inside =
        building.north_m >= sq.north_min_m && building.north_m < sq.north_min_m + sq.size_m &&
        building.east_m >= sq.east_min_m && building.east_m < sq.east_min_m + sq.size_m;
    return inside ? std::vector<terrain::GroundObject>{building}
                  : std::vector<terrain::GroundObject>{};
  }
};

// With objects_3d, a building stands at its height: from 30 m straight above
// the origin, the depth where its roof projects is 30 - 6 = 24 m, where a
// point of its south wall 3 m up projects 27 m, where the ground 9 m north
// projects (the ray clears the roof's north edge at 6.7 m) 30 m; and the
// ground 7.5 m north is hidden: its ray meets the roof at 6 m north, 24 m
// deep. Without objects_3d every one of those pixels sees the ground.
TEST(CameraRenderer, ABuildingStandsAtItsHeight) {
  for (const bool objects : {true, false}) {
    HeadlessGlContext context;
    auto world = std::make_shared<BuildingWorld>();
    terrain::TileParams tile_params;
    tile_params.texture_px = 256;
    auto tiles = std::make_shared<terrain::TileTree>(world, tile_params);
    TerrainRendererParams renderer_params;
    renderer_params.objects_3d = objects;
    renderer_params.objects_max_texel_m = 100.0;
    TerrainRenderer terrain(tiles, renderer_params);
    CameraRenderer camera(terrain, testCamera());
    const Eigen::Isometry3d T_world_cam = downCameraPose({0.0, 0.0, -30.0}, 0.0, 0.0, 0.0);
    const RenderedImage frame = camera.render(T_world_cam, 0, true);
    const CameraIntrinsics& k = camera.intrinsics();
    const auto depthAt = [&](const Eigen::Vector3d& p_world) {
      const Eigen::Vector3d p = T_world_cam.inverse() * p_world;
      const int u = static_cast<int>(std::lround(k.fx * p.x() / p.z() + k.cx));
      const int v = static_cast<int>(std::lround(k.fy * p.y() / p.z() + k.cy));
      return static_cast<double>(frame.depth_m.at<float>(v, u));
    };
    const double roof = depthAt({5.5, 0.5, -6.0});
    const double wall = depthAt({3.0, 0.5, -3.0});
    const double ground_beyond = depthAt({9.0, 0.0, 0.0});
    const double ground_hidden = depthAt({7.5, 0.0, 0.0});
    std::printf("objects %s: depth roof %.3f, wall %.3f, ground beyond %.3f, hidden %.3f m\n",
                objects ? "on" : "off", roof, wall, ground_beyond, ground_hidden);
    EXPECT_NEAR(ground_beyond, 30.0, 0.05);
    if (objects) {
      EXPECT_NEAR(roof, 24.0, 0.05);
      EXPECT_NEAR(wall, 27.0, 0.3);  // a pixel spans 0.1 m of wall at this slant
      EXPECT_NEAR(ground_hidden, 24.0, 0.05);
    } else {
      EXPECT_NEAR(ground_hidden, 30.0, 0.05);
      EXPECT_GT(roof, 29.9);
    }
  }
}

// A concentric ground target appears where it lies, with all its rings: along the row
// through its centre, 5 rings give 10 dark runs, and the dark pixels centre on its projection.
TEST(CameraRenderer, ConcentricTargetIsDrawnWithItsRings) {
  Fixture fixture(1.0);
  terrain::GroundTarget target;
  target.north_m = 100.0;
  target.east_m = 80.0;
  target.size_m = 1.0;
  target.rings = 5;
  target.yaw_deg = 0.0;
  fixture.terrain->setTargets({target});
  CameraRenderer camera(*fixture.terrain, testCamera());
  const Eigen::Isometry3d T_world_cam = downCameraPose({100.05, 79.9, -3.0}, 0.0, 0.0, 0.0);
  const cv::Mat image = camera.render(T_world_cam, 0).image;
  const Eigen::Vector3d centre_cam = T_world_cam.inverse() * Eigen::Vector3d(100.0, 80.0, -1.0);
  const Eigen::Vector2d centre_px = camera.intrinsics().project(centre_cam);
  const int row = static_cast<int>(std::lround(centre_px.y()));
  int dark_runs = 0;
  for (int col = 1; col < image.cols; ++col) {
    if (image.at<std::uint8_t>(row, col) < 70 && image.at<std::uint8_t>(row, col - 1) >= 70)
      ++dark_runs;
  }
  EXPECT_EQ(dark_runs, 10);
  // Darkness below the gray background as weights: anti-aliased ring edges count
  // in proportion, so the centroid is sub-pixel.
  cv::Mat darkness;
  cv::subtract(cv::Scalar(128), image, darkness);
  const cv::Moments m = cv::moments(darkness, false);
  ASSERT_GT(m.m00, 1000.0);
  EXPECT_NEAR(m.m10 / m.m00, centre_px.x(), 0.5);
  EXPECT_NEAR(m.m01 / m.m00, centre_px.y(), 0.5);
}

// The GPU tile cache stays within its budget while flying over many tiles.
TEST(CameraRenderer, TileCacheRespectsItsBudget) {
  HeadlessGlContext context;
  auto world = std::make_shared<terrain::CheckerboardWorld>(kBoard);
  terrain::TileParams tile_params;
  tile_params.texture_px = 64;
  auto tiles = std::make_shared<terrain::TileTree>(world, tile_params);
  TerrainRendererParams params;
  params.tile_cache_mib = 16;
  TerrainRenderer terrain(tiles, params);
  CameraParams camera_params = testCamera();
  camera_params.width = 160;
  camera_params.height = 120;
  CameraRenderer camera(terrain, camera_params);
  std::size_t most = 0;
  for (int i = 0; i < 60; ++i) {
    const RenderedImage frame =
        camera.render(downCameraPose({-150.0 + 5.0 * i, 20.0, -3.0}, 0, 0, 0), i);
    most = std::max(most, terrain.gpuBytes());
    EXPECT_LE(terrain.gpuBytes(), 16u * 1024 * 1024) << "frame " << i;
  }
  EXPECT_GT(most, 8u * 1024 * 1024) << "the flight should have filled the cache";
}

// Tiles made ahead on the prefetcher's thread give the frames of a flight the
// same pixels as tiles made when first drawn: over new ground every frame,
// the second renderer's frames equal the first's, bit for bit, and some of
// its new tiles were made ahead (it is given time between frames).
TEST(CameraRenderer, TilesMadeAheadGiveTheSamePixels) {
  HeadlessGlContext context;
  terrain::ProceduralWorldParams world_params;
  world_params.size_m = 4000.0;
  auto world = std::make_shared<terrain::ProceduralWorld>(world_params);
  terrain::TileParams tile_params;
  tile_params.texture_px = 128;
  TerrainRendererParams made_when_drawn;
  made_when_drawn.prefetch_tiles = false;
  TerrainRendererParams made_ahead;
  made_ahead.prefetch_tiles = true;
  TerrainRenderer terrain_a(std::make_shared<terrain::TileTree>(world, tile_params),
                            made_when_drawn);
  TerrainRenderer terrain_b(std::make_shared<terrain::TileTree>(world, tile_params), made_ahead);
  ASSERT_EQ(terrain_a.prefetcher(), nullptr);
  const terrain::TilePrefetcher& prefetcher = *terrain_b.prefetcher();
  CameraParams params = testCamera();
  params.width = 320;
  params.height = 240;
  params.ground_detail = true;
  CameraRenderer camera_a(terrain_a, params), camera_b(terrain_b, params);
  int uploaded = 0;
  for (int i = 0; i < 24; ++i) {
    // 40 m a frame, two frames a second, 80 m over the ground: new tiles in
    // every frame, and the next frame's in the view expected 0.5 s ahead.
    const double north = -800.0 + 40.0 * i, east = 100.0 + 10.0 * i;
    const Eigen::Isometry3d T_world_cam =
        downCameraPose({north, east, -(world->groundUp_m(north, east) + 80.0)}, 0.05, 0.0, 0.4);
    const std::int64_t utime = 500'000 * (i + 1);
    const RenderedImage a = camera_a.render(T_world_cam, utime);
    const RenderedImage b = camera_b.render(T_world_cam, utime);
    ASSERT_EQ(cv::norm(a.image, b.image, cv::NORM_INF), 0.0) << "frame " << i;
    EXPECT_EQ(a.stats.tiles_uploaded, b.stats.tiles_uploaded) << "frame " << i;
    uploaded += b.stats.tiles_uploaded;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(2);
    while (!prefetcher.idle() && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_GT(uploaded, 48);
  const terrain::TilePrefetchStats stats = prefetcher.stats();
  EXPECT_EQ(stats.taken_ready + stats.made_here, uploaded);
  EXPECT_GT(stats.taken_ready, 0);
}

// ---------------------------------------------------------------- motion

// The thesis's camera (1280x960, 84.872 deg: f = 700 px) 5 m over the board,
// level, nose north: the board's east edges are vertical lines in the image.
CameraParams thesisCamera() {
  CameraParams params;
  params.width = 1280;
  params.height = 960;
  params.hfov_deg = 84.872;
  params.ground_detail = false;
  return params;
}

// Rolling right at 45 deg/s about the nose, in the camera's optical frame.
CameraMotion rollingRight() {
  CameraMotion motion;
  motion.omega_cam_rps =
      core::rotationBodyFromDownCamera().transpose() * Eigen::Vector3d(45.0 * kDeg, 0.0, 0.0);
  return motion;
}

// Sub-pixel position (centroid of |d/dx|) and variance of the line-spread
// function of the edge near x0 along rows [row0, row1).
struct EdgeProfile {
  double x = 0.0;
  double variance = 0.0;
};
EdgeProfile edgeAt(const cv::Mat& image, double x0, int row0, int row1) {
  constexpr int kHalf = 14;
  std::vector<double> weight(2 * kHalf, 0.0);
  const int start = static_cast<int>(std::lround(x0)) - kHalf;
  for (int row = row0; row < row1; ++row) {
    for (int i = 0; i < 2 * kHalf; ++i) {
      weight[i] += std::abs(static_cast<double>(image.at<std::uint8_t>(row, start + i + 1)) -
                            image.at<std::uint8_t>(row, start + i));
    }
  }
  double sum = 0.0, first = 0.0, second = 0.0;
  for (int i = 0; i < 2 * kHalf; ++i) {
    const double x = start + i + 0.5;
    sum += weight[i];
    first += weight[i] * x;
    second += weight[i] * x * x;
  }
  EdgeProfile edge;
  edge.x = first / sum;
  edge.variance = second / sum - edge.x * edge.x;
  return edge;
}

// A 5 ms exposure in a 45 deg/s roll smears the image by f tan(0.225 deg) =
// 2.75 px at the centre (f (tan(a + 0.225 deg) - tan a) at angle a off the
// axis). A box blur of width w adds w^2 / 12 to the edge's line-spread variance,
// and the bilinear lookups at the moving positions (fractions spread evenly
// over a pixel) add the mean of f (1 - f), 1/6 px^2.
TEST(CameraRenderer, MotionBlurSmearsByTheRotationDuringTheExposure) {
  Fixture fixture;
  CameraParams params = thesisCamera();
  params.motion_blur = true;
  params.exposure_s = 0.005;
  params.motion_blur_samples = 16;
  CameraRenderer camera(*fixture.terrain, params);
  const Eigen::Isometry3d T_world_cam = downCameraPose({0.0, 0.0, -5.0}, 0.0, 0.0, 0.0);
  const cv::Mat sharp = camera.render(T_world_cam, 0).image.clone();
  const cv::Mat blurred = camera.render(T_world_cam, 0, false, rollingRight()).image.clone();
  const CameraIntrinsics& k = camera.intrinsics();
  const double x_edge = k.cx + k.fx * fixture.world->cornerEast_m(3) / 5.0;
  const EdgeProfile before = edgeAt(sharp, x_edge, 470, 490);
  const EdgeProfile after = edgeAt(blurred, x_edge, 470, 490);
  const double a = std::atan((x_edge - k.cx) / k.fx);
  const double expected_px = k.fx * (std::tan(a + 0.225 * kDeg) - std::tan(a));
  EXPECT_NEAR(k.fx * std::tan(0.225 * kDeg), 2.75, 0.01);
  EXPECT_NEAR(std::sqrt(12.0 * (after.variance - before.variance - 1.0 / 6.0)), expected_px, 0.15);
  // The exposure is centred on the frame's time: the edge stays where it was.
  EXPECT_NEAR(after.x, before.x, 0.1);
  const cv::Mat again = camera.render(T_world_cam, 0, false, rollingRight()).image;
  EXPECT_EQ(cv::norm(blurred, again, cv::NORM_INF), 0.0) << "the same motion, other bytes";
}

// A 30 ms readout in a 45 deg/s roll: row r is exposed 30 ms (r / 959 - 1/2)
// after the frame's time, so an edge that is vertical with a global shutter
// leans by f (tan(a + w dt) - tan a) between two rows dt apart (16.5 px top to
// bottom at the centre column), the middle row where it was.
TEST(CameraRenderer, RollingShutterShiftsRowsByTheRotationDuringTheReadout) {
  Fixture fixture;
  CameraParams params = thesisCamera();
  params.rolling_shutter = true;
  params.readout_s = 0.03;
  CameraRenderer camera(*fixture.terrain, params);
  const Eigen::Isometry3d T_world_cam = downCameraPose({0.0, 0.0, -5.0}, 0.0, 0.0, 0.0);
  const cv::Mat still = camera.render(T_world_cam, 0).image.clone();
  const cv::Mat rolling = camera.render(T_world_cam, 0, false, rollingRight()).image.clone();
  const CameraIntrinsics& k = camera.intrinsics();
  EXPECT_NEAR(k.fx * std::tan(45.0 * kDeg * 0.03), 16.5, 0.05);
  const double x_edge = k.cx + k.fx * fixture.world->cornerEast_m(3) / 5.0;
  const double a = std::atan((x_edge - k.cx) / k.fx);
  const int top = 40, bottom = 920, band = 4;
  const double dt_s = 0.03 * (bottom - top) / 959.0;
  const double expected_px = k.fx * (std::tan(a + 45.0 * kDeg * dt_s) - std::tan(a));
  const double still_top = edgeAt(still, x_edge, top, top + band).x;
  const double still_bottom = edgeAt(still, x_edge, bottom, bottom + band).x;
  EXPECT_NEAR(still_top, still_bottom, 0.1) << "the edge should be vertical without motion";
  const double lean =
      edgeAt(rolling, x_edge, bottom, bottom + band).x - edgeAt(rolling, x_edge, top, top + band).x;
  EXPECT_NEAR(std::abs(lean), expected_px, 0.3);
  EXPECT_NEAR(edgeAt(rolling, x_edge, 478, 482).x, edgeAt(still, x_edge, 478, 482).x, 0.15);
}

// ---------------------------------------------------------------- exposure

// Over the world's uniform gray (128 counts), away from the board.
const Eigen::Isometry3d kOverGray = downCameraPose({100.0, 100.0, -5.0}, 0.0, 0.0, 0.0);

// Vignetting falls as 1 / (1 + k r^2)^2 with k set so that the corner keeps
// vignetting_corner of the light: k = (1 / sqrt(0.5) - 1) / r_corner^2.
TEST(CameraRenderer, VignettingDarkensTowardsTheCornersAsWorkedOut) {
  Fixture fixture;
  CameraParams params = testCamera();
  params.vignetting = true;
  params.vignetting_corner = 0.5;
  CameraRenderer camera(*fixture.terrain, params);
  const cv::Mat image = camera.render(kOverGray, 0).image;
  const CameraIntrinsics& k = camera.intrinsics();
  const auto r2 = [&](double u, double v) {
    return std::pow((u - k.cx) / k.fx, 2) + std::pow((v - k.cy) / k.fy, 2);
  };
  const double kk = (1.0 / std::sqrt(0.5) - 1.0) / r2(0.0, 0.0);
  for (const auto& [u, v] :
       std::vector<std::pair<int, int>>{{320, 240}, {0, 0}, {160, 120}, {639, 479}, {600, 100}}) {
    const double expected = 128.0 / std::pow(1.0 + kk * r2(u, v), 2);
    EXPECT_NEAR(image.at<std::uint8_t>(v, u), expected, 1.0) << "pixel " << u << ", " << v;
  }
  EXPECT_NEAR(image.at<std::uint8_t>(0, 0), 64.0, 1.0);
}

// The VOs' calibration divides out what the renderer's lens and response
// did: the world's uniform 128-count gray, vignetted to half at the corners
// and through a gamma of 2.2, comes back within two counts of the same gray
// frame without vignetting, over the whole image.
TEST(CameraRenderer, TheVosVignettingCorrectionUndoesTheLens) {
  Fixture fixture;
  CameraParams params = testCamera();
  params.response_curve = true;
  params.response_gamma = 2.2;
  CameraRenderer flat_camera(*fixture.terrain, params);
  const cv::Mat flat = flat_camera.render(kOverGray, 0).image;
  params.vignetting = true;
  params.vignetting_corner = 0.5;
  CameraRenderer camera(*fixture.terrain, params);
  const cv::Mat vignetted = camera.render(kOverGray, 0).image;
  const CameraIntrinsics& k = camera.intrinsics();
  const cv::Matx33d K(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  vo::VignettingCorrection correction;
  const cv::Mat corrected =
      correction.apply(vignetted, K, {.vignetting_corner = 0.5, .response_gamma = 2.2});
  cv::Mat difference;
  cv::absdiff(corrected, flat, difference);
  double worst = 0.0;
  cv::minMaxLoc(difference, nullptr, &worst);
  EXPECT_LE(worst, 2.0);
  EXPECT_GT(cv::norm(vignetted, flat, cv::NORM_INF), 40.0) << "the lens should darken the corners";
}

// A gamma response: 255 (128 / 255)^(1 / 2.2) = 186.4 counts.
TEST(CameraRenderer, ResponseCurveMapsCountsThroughTheGamma) {
  Fixture fixture;
  CameraParams params = testCamera();
  params.response_curve = true;
  params.response_gamma = 2.2;
  CameraRenderer camera(*fixture.terrain, params);
  const cv::Mat image = camera.render(kOverGray, 0).image;
  EXPECT_NEAR(cv::mean(image)[0], 186.4, 0.6);
}

// Auto-exposure towards 64 counts over a 128-count scene at 31 frames/s, tau
// 0.3 s: each frame moves log g by a = 1 - e^(-dt / tau) of the way, so frame
// n reads 128 (64 / 128)^(1 - (1 - a)^n).
TEST(CameraRenderer, AutoExposureSettlesWithItsTimeConstant) {
  Fixture fixture;
  CameraParams params = testCamera();
  params.auto_exposure = true;
  params.ae_target_counts = 64.0;
  params.ae_time_constant_s = 0.3;
  CameraRenderer camera(*fixture.terrain, params);
  constexpr std::int64_t kFrameUs = 32258;
  const double a = 1.0 - std::exp(-kFrameUs * 1e-6 / 0.3);
  for (int n = 0; n <= 40; ++n) {
    const double mean = cv::mean(camera.render(kOverGray, n * kFrameUs).image)[0];
    const double expected = 128.0 * std::pow(0.5, 1.0 - std::pow(1.0 - a, n));
    if (n == 0 || n == 1 || n == 5 || n == 10 || n == 40) {
      EXPECT_NEAR(mean, expected, 1.0) << "frame " << n;
    }
  }
  EXPECT_NEAR(camera.exposureGain(), 0.5, 0.01);
}

}  // namespace
}  // namespace nadir::render
