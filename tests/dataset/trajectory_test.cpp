// Interpolation of the truth at image times: linear position, SLERP orientation.

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "core/frames.h"
#include "dataset/trajectory.h"

namespace nadir::dataset {
namespace {

TruthSample sample(std::int64_t utime, const Eigen::Vector3d& p, double yaw_rad) {
  TruthSample s;
  s.utime = utime;
  s.p_body_in_world_m = p;
  s.q_world_body = core::quaternionFromRpy({.yaw_rad = yaw_rad});
  return s;
}

const std::vector<TruthSample> kTwo = {sample(1000, {0, 0, 0}, 0.0),
                                       sample(2000, {1, 2, 3}, std::numbers::pi / 2)};

// A quarter of the way from (0,0,0), yaw 0 to (1,2,3), yaw 90 deg: (0.25, 0.5, 0.75), yaw 22.5 deg.
TEST(Trajectory, InterpolatesLinearlyAndWithSlerp) {
  const auto T = interpolatePose(kTwo, 1250, 10'000);
  ASSERT_TRUE(T);
  EXPECT_NEAR(T->translation().x(), 0.25, 1e-12);
  EXPECT_NEAR(T->translation().y(), 0.5, 1e-12);
  EXPECT_NEAR(T->translation().z(), 0.75, 1e-12);
  const core::RollPitchYaw rpy = core::rpyFromRotation(T->rotation());
  EXPECT_NEAR(rpy.yaw_rad, std::numbers::pi / 8, 1e-12);
  EXPECT_NEAR(rpy.roll_rad, 0.0, 1e-12);
  EXPECT_NEAR(rpy.pitch_rad, 0.0, 1e-12);
}

// At a sample's own time the sample comes back exactly.
TEST(Trajectory, ReturnsSamplesAtTheirTimes) {
  const auto T = interpolatePose(kTwo, 2000, 10'000);
  ASSERT_TRUE(T);
  EXPECT_EQ(T->translation(), Eigen::Vector3d(1, 2, 3));
  EXPECT_NEAR(core::rpyFromRotation(T->rotation()).yaw_rad, std::numbers::pi / 2, 1e-12);
}

// Nothing outside the truth's span or across a gap wider than allowed.
TEST(Trajectory, NothingOutsideTheSpanOrAcrossAGap) {
  EXPECT_FALSE(interpolatePose(kTwo, 999, 10'000));
  EXPECT_FALSE(interpolatePose(kTwo, 2001, 10'000));
  EXPECT_FALSE(interpolatePose(kTwo, 1500, 999));
  EXPECT_FALSE(interpolatePose({}, 1500, 10'000));
}

// SLERP takes the short way even when the second quaternion has the other sign.
TEST(Trajectory, SlerpTakesTheShortArc) {
  std::vector<TruthSample> samples = kTwo;
  samples[1].q_world_body.coeffs() *= -1.0;
  const auto T = interpolatePose(samples, 1500, 10'000);
  ASSERT_TRUE(T);
  EXPECT_NEAR(core::rpyFromRotation(T->rotation()).yaw_rad, std::numbers::pi / 4, 1e-12);
}

}  // namespace
}  // namespace nadir::dataset
