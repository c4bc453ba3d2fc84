// The gate tracker on rendered course boards: a gate seen by a rover's
// forward PPA camera at 1, 2 and 4 m, head-on and 20 deg off its axis, gives
// disk centres within 1 px of the pinhole projection of the true disk centres
// (worked out here from the board's drawing: 0.45 m board 0.2 m above the
// floor, disks at 0.38 and 0.62 of its side). Slalom boards read their side,
// turn boards their turn; decoys alone are never a gate.

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>

#include "bench/ppa_scenes.h"
#include "nodes/control/gate_controller.h"
#include "nodes/ppa/gate_tracker.h"
#include "render/camera_renderer.h"
#include "render/egl_context.h"
#include "render/terrain_renderer.h"
#include "terrain/arena_world.h"
#include "terrain/course.h"
#include "terrain/tiles.h"

namespace nadir::ppa {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kBoard_m = 0.45;
constexpr double kClearance_m = 0.2;
constexpr double kPost_m = 0.03;
constexpr double kCameraUp_m = 0.12;
constexpr double kTilt_deg = 10.0;
constexpr double kHfov_deg = 50.0;

struct Scene {
  render::HeadlessGlContext context;
  std::shared_ptr<terrain::TileTree> tiles;
  std::unique_ptr<render::TerrainRenderer> terrain;
  std::unique_ptr<render::CameraRenderer> camera;

  explicit Scene(const std::vector<terrain::CourseBoard>& boards) {
    auto world = std::make_shared<terrain::ArenaWorld>(terrain::ArenaParams{});
    tiles = std::make_shared<terrain::TileTree>(world, terrain::TileParams{});
    terrain = std::make_unique<render::TerrainRenderer>(tiles, render::TerrainRendererParams{});
    terrain->setBoards(boards);
    render::CameraParams params;
    params.width = params.height = 256;
    params.hfov_deg = kHfov_deg;
    params.near_m = 0.02;
    params.far_m = 200.0;
    camera = std::make_unique<render::CameraRenderer>(*terrain, params);
  }
};

terrain::CourseBoard boardAtOrigin(const char* kind) {
  terrain::CourseBoard board;
  board.kind = kind;
  board.board_m = kBoard_m;
  board.clearance_m = kClearance_m;
  board.post_m = kPost_m;
  return board;
}

// A camera kCameraUp_m above the floor, `distance_m` from the board's centre
// line along a ray `off_axis_deg` from its axis (towards the west), looking
// at the board's foot line and tilted up by kTilt_deg. Optical axes: z
// forward, x right, y down.
Eigen::Isometry3d cameraAt(double distance_m, double off_axis_deg) {
  const double a = off_axis_deg * kDeg;
  const Eigen::Vector3d position(-distance_m * std::cos(a), -distance_m * std::sin(a),
                                 -kCameraUp_m);
  const double yaw = a;  // facing the board
  const double t = kTilt_deg * kDeg;
  const Eigen::Vector3d forward(std::cos(yaw) * std::cos(t), std::sin(yaw) * std::cos(t),
                                -std::sin(t));
  const Eigen::Vector3d right(-std::sin(yaw), std::cos(yaw), 0.0);
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = right;
  T.linear().col(1) = down;
  T.linear().col(2) = forward;
  T.translation() = position;
  return T;
}

// The projection of the disk at pattern fractions (x, y) of a board at the
// origin facing north.
std::array<double, 2> projectDisk(const Eigen::Isometry3d& T_world_cam, double x, double y) {
  const double face_north_m = -(0.5 * kPost_m + 0.002);
  const Eigen::Vector3d p_world(face_north_m, (x - 0.5) * kBoard_m,
                                -(kClearance_m + (1.0 - y) * kBoard_m));
  const Eigen::Vector3d p = T_world_cam.inverse() * p_world;
  const double f = 128.0 / std::tan(0.5 * kHfov_deg * kDeg);
  return {127.5 + f * p.x() / p.z(), 127.5 + f * p.y() / p.z()};
}

// The evenly lit arena is read with the linear response at half gain (PIX =
// gray / 2) and a threshold of gray 104: thin lines keep their contrast, which
// the log response compresses in the bright half.
GateTrackerParams trackerParams() {
  GateTrackerParams params;
  params.threshold = 52.0;
  return params;
}

GateResult trackImage(GateTracker& tracker, const cv::Mat& image) {
  PpaParams array;
  array.pix_response = "linear";
  array.pix_gain = 0.5;
  Ppa ppa(array);
  test::expose(ppa, image);
  return tracker.processFrame(ppa);
}

TEST(GateCourseTest, DiskCentresWithinOnePixelOfTheProjection) {
  Scene scene({boardAtOrigin("gate")});
  for (const double distance : {1.0, 2.0, 4.0}) {
    for (const double off_axis : {0.0, 20.0}) {
      SCOPED_TRACE("distance " + std::to_string(distance) + " m, " + std::to_string(off_axis) +
                   " deg off axis");
      const Eigen::Isometry3d T = cameraAt(distance, off_axis);
      const cv::Mat image = scene.camera->render(T, 0).image;
      GateTracker tracker{trackerParams()};
      const GateResult result = trackImage(tracker, image);
      ASSERT_EQ(result.kind, PatternKind::kGate);
      EXPECT_TRUE(result.squares_intact);
      const double xs[4] = {0.38, 0.62, 0.38, 0.62}, ys[4] = {0.38, 0.38, 0.62, 0.62};
      for (int i = 0; i < 4; ++i) {
        const auto expected = projectDisk(T, xs[i], ys[i]);
        EXPECT_NEAR(result.disk_centres_px[i][0], expected[0], 1.0) << "disk " << i;
        EXPECT_NEAR(result.disk_centres_px[i][1], expected[1], 1.0) << "disk " << i;
      }
    }
  }
}

TEST(GateCourseTest, SlalomBoardsSayWhichWay) {
  for (const auto& [kind, expected] : {std::pair{"slalom_right", PatternKind::kSlalomRight},
                                       std::pair{"slalom_left", PatternKind::kSlalomLeft}}) {
    Scene scene({boardAtOrigin(kind)});
    for (const double distance : {1.0, 2.5}) {
      GateTracker tracker{trackerParams()};
      const GateResult result =
          trackImage(tracker, scene.camera->render(cameraAt(distance, 10.0), 0).image);
      EXPECT_EQ(result.kind, expected) << kind << " at " << distance << " m";
      EXPECT_EQ(result.num_disks, 3);
    }
  }
}

// A turn board's single disk, a quarter of its column above or below the
// column's middle (135 or 45 deg), or level with it (pass the board), read by
// the chip at 1, 2.5 and 4 m, 10 deg off its axis, and by the controller's
// reading of the disks: the turn the board asks for.
TEST(GateCourseTest, TurnBoardsSayHowFar) {
  for (const char* kind : {"slalom_right", "slalom_left"}) {
    for (const double turn_deg : {0.0, 45.0, 135.0}) {
      terrain::CourseBoard board = boardAtOrigin(kind);
      board.turn_deg = turn_deg;
      Scene scene({board});
      for (const double distance : {1.0, 2.5, 4.0}) {
        GateTracker tracker{trackerParams()};
        const GateResult result =
            trackImage(tracker, scene.camera->render(cameraAt(distance, 10.0), 0).image);
        ASSERT_EQ(result.num_disks, 3) << kind << " " << turn_deg << " at " << distance << " m";
        control::PatternObservation seen;
        seen.kind = result.kind == PatternKind::kSlalomRight  ? control::Pattern::kSlalomRight
                    : result.kind == PatternKind::kSlalomLeft ? control::Pattern::kSlalomLeft
                                                              : control::Pattern::kNone;
        for (int i = 0; i < 3; ++i) {
          seen.disks_px.emplace_back(result.disk_centres_px[i][0], result.disk_centres_px[i][1]);
        }
        EXPECT_EQ(control::boardTurn_deg(seen, control::SlalomParams{}), turn_deg)
            << kind << " at " << distance << " m";
      }
    }
  }
}

// Every decoy pattern, similar and random, alone in view at 1 and 2 m: no
// gate and no slalom board.
TEST(GateCourseTest, ADecoyAloneIsNeverAGate) {
  std::vector<terrain::CourseBoard> decoys;
  for (const char* pattern : {"similar", "random"}) {
    for (std::int64_t seed = 0; seed < 10; ++seed) {
      terrain::CourseBoard decoy = boardAtOrigin("decoy");
      decoy.decoy_pattern = pattern;
      decoy.seed = seed;
      decoy.east_m = 8.0 * static_cast<double>(decoys.size());
      decoys.push_back(decoy);
    }
  }
  Scene scene(decoys);
  for (const terrain::CourseBoard& decoy : decoys) {
    for (const double distance : {1.0, 2.0}) {
      Eigen::Isometry3d T = cameraAt(distance, 0.0);
      T.translation().y() += decoy.east_m;
      GateTracker tracker{trackerParams()};
      const GateResult result = trackImage(tracker, scene.camera->render(T, 0).image);
      EXPECT_EQ(result.kind, PatternKind::kNone)
          << decoy.decoy_pattern << " decoy, seed " << decoy.seed << ", at " << distance << " m";
    }
  }
}

// A gate with a decoy of the similar kind right beside it: the gate is found.
TEST(GateCourseTest, TheGateBesideItsDecoys) {
  terrain::CourseBoard left = boardAtOrigin("decoy"), right = boardAtOrigin("decoy");
  left.east_m = -0.8;
  left.seed = 1;  // two squares, two disks
  right.east_m = 0.8;
  right.seed = 4;  // two squares, four disks in a row
  Scene scene({boardAtOrigin("gate"), left, right});
  GateTracker tracker{trackerParams()};
  const GateResult result = trackImage(tracker, scene.camera->render(cameraAt(3.0, 0.0), 0).image);
  EXPECT_EQ(result.kind, PatternKind::kGate);
  EXPECT_NEAR(0.5 * (result.box.x_min + result.box.x_max), 127.5, 3.0);
}

}  // namespace
}  // namespace nadir::ppa
