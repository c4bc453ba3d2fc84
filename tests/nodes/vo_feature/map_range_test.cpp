// The map's range along the rangefinder's ray, from a plane through the points
// near it (nodes/vo_feature/map_range.h).

#include "nodes/vo_feature/map_range.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

namespace nadir::vo {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// Ground 300 m from the camera along the normal (0, sin a, cos a): a camera
// banked by a about its x axis. Along the optical axis the range is
// 300 / cos a, worked out by hand.
struct TiltedGround {
  double bank_rad = 30.0 * kDeg;
  double distance_m = 300.0;
  Eigen::Vector3d normal() const { return {0.0, std::sin(bank_rad), std::cos(bank_rad)}; }
  // The ground point at (x, y) in the camera's x and y.
  Eigen::Vector3d at(double x, double y) const {
    return {x, y, (distance_m - y * std::sin(bank_rad)) / std::cos(bank_rad)};
  }
  double rangeOnAxis_m() const { return distance_m / std::cos(bank_rad); }
};

TEST(MapRange, PointsOnOneSideOfTheRayGiveTheRangeToTheirPlaneNotTheirMedian) {
  const TiltedGround ground;
  std::vector<Eigen::Vector3d> points;
  // Only the half of the patch a bank has already mapped: y from 10 to 60 m.
  for (double x = -60.0; x <= 60.0; x += 10.0)
    for (double y = 10.0; y <= 60.0; y += 5.0) points.push_back(ground.at(x, y));
  const std::optional<double> range = rangeToPlaneAlongRay(points, Eigen::Vector3d::UnitZ());
  ASSERT_TRUE(range);
  EXPECT_NEAR(*range, 346.410, 1e-3);
  EXPECT_NEAR(*range, ground.rangeOnAxis_m(), 1e-9);
  // What the median of the points' ranges along the ray would have said: the median point, 35 m off
  // the ray, is 6 % short.
  std::vector<double> along;
  for (const Eigen::Vector3d& p : points) along.push_back(p.z());
  std::nth_element(along.begin(), along.begin() + static_cast<std::ptrdiff_t>(along.size() / 2),
                   along.end());
  EXPECT_LT(along[along.size() / 2], 0.95 * ground.rangeOnAxis_m());
}

TEST(MapRange, NoisyPointsAndRoofsAboveTheGroundStillGiveTheGroundsRange) {
  const TiltedGround ground;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise_m(0.0, 0.5);
  std::uniform_real_distribution<double> coordinate_m(-50.0, 50.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 200; ++i) {
    Eigen::Vector3d p =
        ground.at(coordinate_m(rng), coordinate_m(rng)) + noise_m(rng) * ground.normal();
    // One point in ten is a roof 12 m above the ground, towards the camera.
    if (i % 10 == 0) p -= 12.0 * ground.normal();
    points.push_back(p);
  }
  const std::optional<double> range = rangeToPlaneAlongRay(points, Eigen::Vector3d::UnitZ());
  ASSERT_TRUE(range);
  // 0.5 m noise over 180 ground points: the plane's offset is good to ~0.04 m,
  // its tilt to ~0.1 mrad; left in, the roofs would pull it 1.4 m closer.
  EXPECT_NEAR(*range, ground.rangeOnAxis_m(), 0.3);
}

TEST(MapRange, TooFewPointsAPlaneSeenEdgeOnOrBehindGiveNoRange) {
  const TiltedGround ground;
  std::vector<Eigen::Vector3d> few;
  for (int i = 0; i < static_cast<int>(kMinPlanePoints) - 1; ++i)
    few.push_back(ground.at(10.0 * i, 5.0 * (i % 3)));
  EXPECT_FALSE(rangeToPlaneAlongRay(few, Eigen::Vector3d::UnitZ()));

  // A wall along the ray: the plane x = 20 contains the ray's direction.
  std::vector<Eigen::Vector3d> wall;
  for (double y = -30.0; y <= 30.0; y += 10.0)
    for (double z = 100.0; z <= 300.0; z += 50.0) wall.emplace_back(20.0, y, z);
  EXPECT_FALSE(rangeToPlaneAlongRay(wall, Eigen::Vector3d::UnitZ()));

  std::vector<Eigen::Vector3d> behind;
  for (double x = -30.0; x <= 30.0; x += 10.0)
    for (double y = -30.0; y <= 30.0; y += 10.0) behind.emplace_back(x, y, -200.0);
  EXPECT_FALSE(rangeToPlaneAlongRay(behind, Eigen::Vector3d::UnitZ()));
}

// The scale upkeep's factor, worked out by hand: within the tolerance none; a
// ratio of 1.01 at gain 0.5 is 1 - 0.5 * 0.01 / 1.01; the wild ratios of a bad
// plane (0.29 would scale the map by 2.22, 2.21 by 0.726) stop at 2 %.
TEST(ScaleCorrection, HalfTheErrorWithinTheLargestStep) {
  EXPECT_EQ(scaleCorrection(1.0015, 0.002, 0.5, 0.02), 1.0);
  EXPECT_EQ(scaleCorrection(0.9985, 0.002, 0.5, 0.02), 1.0);
  EXPECT_NEAR(scaleCorrection(1.01, 0.002, 0.5, 0.02), 1.0 - 0.005 / 1.01, 1e-15);
  EXPECT_NEAR(scaleCorrection(0.99, 0.002, 0.5, 0.02), 1.0 + 0.005 / 0.99, 1e-15);
  EXPECT_EQ(scaleCorrection(0.29, 0.002, 0.5, 0.02), 1.02);
  EXPECT_EQ(scaleCorrection(2.21, 0.002, 0.5, 0.02), 0.98);
  EXPECT_EQ(scaleCorrection(0.0, 0.002, 0.5, 0.02), 1.0);  // no range: nothing to correct
}

}  // namespace
}  // namespace nadir::vo
