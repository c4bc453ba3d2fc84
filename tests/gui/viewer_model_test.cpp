// nadir-viewer's model without a display: interpolation of a trajectory at a
// playback time, the polylines drawn up to it, and the orbit camera's geometry.
#include "gui/viewer_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/frames.h"
#include "gui_test_util.h"

namespace nadir::gui {
namespace {

core::Trajectory line(const std::vector<double>& stamps) {
  core::Trajectory s;
  for (double t : stamps) s.push_back({t, test::truthPosition(t), Eigen::Quaterniond::Identity()});
  return s;
}

// A source whose TRACKING stretches are these (a LOST estimate between them).
SourceSeries source(std::vector<core::Trajectory> stretches) {
  SourceSeries s;
  s.tracked = std::move(stretches);
  return s;
}

TEST(GuiViewerModel, PositionIsTheTruthInterpolated) {
  const RunData run = loadRun(test::writeTumRun("model").string());
  for (double t : {100.0, 100.05, 103.37, 109.99, 110.0}) {
    const auto p = positionAt(run.truth, t);
    ASSERT_TRUE(p) << t;
    EXPECT_LT((*p - test::truthPosition(t)).norm(), 1e-9) << t;
  }
  EXPECT_FALSE(positionAt(run.truth, 99.99));
  EXPECT_FALSE(positionAt(run.truth, 110.01));
  EXPECT_DOUBLE_EQ(playbackDuration({run}), 10.0);
}

TEST(GuiViewerModel, NoPositionAcrossAGapOrAMissingPose) {
  // The estimate at 4.0 s is LOST.
  const SourceSeries s = source({line({0.0, 0.5, 3.0, 3.5})});
  EXPECT_TRUE(positionAt(s, 0.25));
  EXPECT_FALSE(positionAt(s, 2.0));
  EXPECT_FALSE(positionAt(s, 3.75));
}

TEST(GuiViewerModel, TrackGrowsToTheTimeAndBreaksAtGaps) {
  // Samples at 0, 0.5, 1, 3, 3.5, 4 (LOST) and 4.5 s.
  const SourceSeries s = source({line({0.0, 0.5, 1.0, 3.0, 3.5}), line({4.5})});
  const auto lines = trackUpTo(s, 3.25);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].size(), 3u);
  ASSERT_EQ(lines[1].size(), 2u);
  EXPECT_LT((lines[1].back() - test::truthPosition(3.25)).norm(), 1e-9);
  const auto all = trackUpTo(s, 10.0);
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all[2].size(), 1u);
  EXPECT_TRUE(trackUpTo(s, -1.0).empty());
}

TEST(GuiViewerModel, OrbitCameraLooksAtItsTarget) {
  OrbitCamera camera;
  camera.fit(Eigen::Vector3d(-100, -50, -120), Eigen::Vector3d(300, 250, -80));
  const Eigen::Vector3d target(100, 100, -100);
  EXPECT_LT((camera.target - target).norm(), 1e-9);
  const auto centre = projectToPixel(camera, 640, 480, target);
  ASSERT_TRUE(centre);
  EXPECT_NEAR(centre->x(), 319.5, 1e-6);
  EXPECT_NEAR(centre->y(), 239.5, 1e-6);
  // Looking north: a point east of the target is right of the centre, one further
  // north is above it (further away, so higher in the picture).
  EXPECT_GT(projectToPixel(camera, 640, 480, target + Eigen::Vector3d(0, 10, 0))->x(), 320.0);
  EXPECT_LT(projectToPixel(camera, 640, 480, target + Eigen::Vector3d(10, 0, 0))->y(), 239.0);
  // Behind the camera: nothing.
  const Eigen::Vector3d behind = camera.worldFromCamera() * Eigen::Vector3d(0, 0, -5);
  EXPECT_FALSE(projectToPixel(camera, 640, 480, behind));
  for (int i = 0; i < 100; ++i) camera.rotate(0, 50);
  EXPECT_LT(camera.elevation_rad, 1.56);
  EXPECT_TRUE(camera.worldFromCamera().linear().allFinite());
  const double d = camera.distance_m;
  camera.zoom(0.5);
  EXPECT_DOUBLE_EQ(camera.distance_m, d * 0.5);
}

// The attitude halfway between yaw 170 deg and -170 deg is yaw 180 deg (the short
// way round, not 0), at roll 10 deg throughout; none outside the span or across a gap.
TEST(GuiViewerModel, AttitudeIsInterpolatedTheShortWayRound) {
  constexpr double kRad = std::numbers::pi / 180.0;
  core::Trajectory s = line({0.0, 1.0, 5.0});
  for (std::size_t i = 0; i < s.size(); ++i) {
    s[i].q_world_body =
        core::quaternionFromRpy({10.0 * kRad, 0.0, (i == 0 ? 170.0 : -170.0) * kRad});
  }
  const auto q = attitudeAt(s, 0.5);
  ASSERT_TRUE(q);
  const Eigen::Quaterniond expected = core::quaternionFromRpy({10.0 * kRad, 0.0, 180.0 * kRad});
  EXPECT_LT(q->angularDistance(expected), 1e-9);
  EXPECT_FALSE(attitudeAt(s, -0.1));
  EXPECT_FALSE(attitudeAt(s, 3.0));
  ASSERT_TRUE(attitudeAt(s, 5.0));
}

}  // namespace
}  // namespace nadir::gui
