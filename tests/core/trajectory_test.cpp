// The trajectory type: TUM I/O, interpolation and path length, on hand-made
// trajectories.

#include <cmath>
#include <fstream>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "core/trajectory.h"

namespace nadir::core {
namespace {

std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + "nadir_trajectory_" + name;
}

void writeText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

std::string errorOf(const std::string& path) {
  try {
    readTum(path);
  } catch (const TrajectoryError& error) {
    return error.what();
  }
  return "";
}

StampedPose poseAt(double t, double x, double y, double z, double yaw_deg = 0) {
  StampedPose pose;
  pose.t_s = t;
  pose.p_ned_m = Eigen::Vector3d(x, y, z);
  pose.q_world_body = Eigen::Quaterniond(
      Eigen::AngleAxisd(yaw_deg * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ()));
  return pose;
}

// writeTum then readTum gives back the same doubles bit for bit.
TEST(Tum, RoundTripIsExact) {
  Trajectory trajectory;
  trajectory.push_back(poseAt(1700000000.123456, 1.0 / 3.0, -2e-7, 1e6, 10));
  trajectory.push_back(poseAt(1700000000.155714, 0.1, 0.2, 0.3, -170));
  const std::string path = tempPath("roundtrip.tum");
  writeTum(path, trajectory);
  const Trajectory read = readTum(path);
  ASSERT_EQ(read.size(), trajectory.size());
  for (std::size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].t_s, trajectory[i].t_s);
    EXPECT_EQ(read[i].p_ned_m, trajectory[i].p_ned_m);
    EXPECT_NEAR(read[i].q_world_body.angularDistance(trajectory[i].q_world_body), 0.0, 1e-15);
  }
}

// Comments, blank lines, tabs and commas are accepted; fields are t x y z qx qy qz qw.
TEST(Tum, ReadsFieldsInTumOrder) {
  const std::string path = tempPath("fields.tum");
  writeText(path, "# timestamp tx ty tz qx qy qz qw\n\n0.5\t1 2 3 0 0 0 1\n1.5,4,5,6,0,0,1,0\n");
  const Trajectory read = readTum(path);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[0].t_s, 0.5);
  EXPECT_EQ(read[0].p_ned_m, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(read[1].p_ned_m, Eigen::Vector3d(4, 5, 6));
  EXPECT_DOUBLE_EQ(read[1].q_world_body.z(), 1.0);  // qz = 1: 180 deg about z
  EXPECT_DOUBLE_EQ(read[1].q_world_body.w(), 0.0);
}

// A short line is refused with the file, the line number and what is wrong.
TEST(Tum, MalformedLineNamesFileAndLine) {
  const std::string path = tempPath("short.tum");
  writeText(path, "0 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n2 0 0 0 0\n");
  const std::string error = errorOf(path);
  EXPECT_NE(error.find(path + ":3:"), std::string::npos) << error;
  EXPECT_NE(error.find("expected 8 numbers"), std::string::npos) << error;
}

// A field that is not a number is named by its position and text.
TEST(Tum, NonNumberFieldIsNamed) {
  const std::string path = tempPath("word.tum");
  writeText(path, "0 abc 0 0 0 0 0 1\n");
  const std::string error = errorOf(path);
  EXPECT_NE(error.find(path + ":1:"), std::string::npos) << error;
  EXPECT_NE(error.find("field 2 'abc'"), std::string::npos) << error;
}

// Missing file, empty file, zero quaternion and a stamp going back are errors.
TEST(Tum, OtherErrorsAreClear) {
  EXPECT_NE(errorOf(tempPath("missing.tum")).find("cannot open"), std::string::npos);
  const std::string empty = tempPath("empty.tum");
  writeText(empty, "# nothing\n");
  EXPECT_NE(errorOf(empty).find("no poses"), std::string::npos);
  const std::string zero_q = tempPath("zero_q.tum");
  writeText(zero_q, "0 0 0 0 0 0 0 0\n");
  EXPECT_NE(errorOf(zero_q).find("quaternion"), std::string::npos);
  const std::string back = tempPath("back.tum");
  writeText(back, "1 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n");
  EXPECT_NE(errorOf(back).find(back + ":2:"), std::string::npos);
}

// A quaternion of components near the largest double is still a rotation:
// (0, 0, 1e308, 1e308) is 90 deg about z, (qw, qz) = (sqrt(1/2), sqrt(1/2))
// (found by fuzzing: the plain norm overflowed to infinity, the quaternion came
// back zero; fuzz/regressions/trajectory).
TEST(Tum, HugeQuaternionComponentsAreARotation) {
  const std::string huge = tempPath("huge_q.tum");
  writeText(huge, "0 0 0 0 0 0 1e308 1e308\n");
  const Trajectory trajectory = readTum(huge);
  ASSERT_EQ(trajectory.size(), 1u);
  EXPECT_NEAR(trajectory[0].q_world_body.w(), std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(trajectory[0].q_world_body.z(), std::sqrt(0.5), 1e-15);
  EXPECT_EQ(trajectory[0].q_world_body.x(), 0.0);
}

// Linear position and SLERP attitude between samples; nothing outside the span or over a hole.
TEST(Interpolate, LinearPositionSlerpAttitude) {
  const Trajectory truth = {poseAt(0, 0, 0, 0, 0), poseAt(1, 10, 0, -4, 90),
                            poseAt(5, 10, 0, -4, 90)};
  const auto quarter = interpolate(truth, 0.25);
  ASSERT_TRUE(quarter.has_value());
  EXPECT_NEAR((quarter->p_ned_m - Eigen::Vector3d(2.5, 0, -1)).norm(), 0, 1e-12);
  EXPECT_NEAR(quarter->q_world_body.angularDistance(poseAt(0, 0, 0, 0, 22.5).q_world_body), 0,
              1e-12);
  const auto at_sample = interpolate(truth, 1.0);
  ASSERT_TRUE(at_sample.has_value());
  EXPECT_EQ(at_sample->p_ned_m, truth[1].p_ned_m);
  EXPECT_FALSE(interpolate(truth, -0.001).has_value());
  EXPECT_FALSE(interpolate(truth, 5.001).has_value());
  EXPECT_TRUE(interpolate(truth, 3.0, 5.0).has_value());
  EXPECT_FALSE(interpolate(truth, 3.0, 2.0).has_value());  // samples 4 s apart around t = 3
  EXPECT_TRUE(interpolate(truth, 0.5, 2.0).has_value());
}

// SLERP takes the short way even when the second quaternion has the other sign.
TEST(Interpolate, SlerpTakesTheShortArc) {
  Trajectory truth = {poseAt(0, 0, 0, 0, 0), poseAt(1, 0, 0, 0, 90)};
  truth[1].q_world_body.coeffs() *= -1.0;
  const auto mid = interpolate(truth, 0.5);
  ASSERT_TRUE(mid.has_value());
  EXPECT_NEAR(mid->q_world_body.angularDistance(poseAt(0, 0, 0, 0, 45).q_world_body), 0, 1e-12);
}

// Track length is the sum of the straight segments: 3-4-5 triangle legs.
TEST(TrackLength, SumOfSegments) {
  const Trajectory path = {poseAt(0, 0, 0, 0), poseAt(1, 3, 4, 0), poseAt(2, 3, 4, 12)};
  EXPECT_DOUBLE_EQ(trackLength(path), 5.0 + 12.0);
  EXPECT_EQ(trackLength({}), 0.0);
}

}  // namespace
}  // namespace nadir::core
