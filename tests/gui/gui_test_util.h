#pragma once
// A tiny run directory for the plot viewer's tests, with errors known by
// construction: the truth flies a straight line at (10, 5, 0) m/s for 10 s from
// t = 100 s, sampled at 10 Hz, at a constant attitude (roll 5, pitch -10,
// yaw 30 deg); the source "vo_test" estimates at 2 Hz from t = 100.5 s to
// 109.5 s (19 estimates) with the truth's attitude and its position moved by
// (3, 4, 0) m, so every position error is exactly 5 m.

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/bus.h"
#include "core/frames.h"
#include "core/lcm_log.h"
#include "logs/eval/run_metrics.h"
#include "logs/eval/trajectory.h"
#include "nadir/pose_t.hpp"
#include "nadir/vo_estimate_t.hpp"
#include "tests/support/lcm_messages.h"

namespace nadir::gui::test {

inline constexpr double kT0 = 100.0;
inline constexpr int kTruthPoses = 101;
inline constexpr int kEstimates = 19;
inline constexpr double kRollDeg = 5.0;
inline constexpr double kPitchDeg = -10.0;
inline constexpr double kYawDeg = 30.0;
inline const Eigen::Vector3d kOffset(3.0, 4.0, 0.0);

inline Eigen::Quaterniond attitude() {
  constexpr double kRad = std::numbers::pi / 180.0;
  return core::quaternionFromRpy({kRollDeg * kRad, kPitchDeg * kRad, kYawDeg * kRad});
}

inline Eigen::Vector3d truthPosition(double t_s) {
  const double dt = t_s - kT0;
  return Eigen::Vector3d(10.0 * dt, 5.0 * dt, -100.0);
}

inline double truthStamp(int k) { return kT0 + 0.1 * k; }
inline double estimateStamp(int j) { return kT0 + 0.5 + 0.5 * j; }

inline core::Trajectory truthTrajectory() {
  core::Trajectory truth;
  for (int k = 0; k < kTruthPoses; ++k) {
    truth.push_back({truthStamp(k), truthPosition(truthStamp(k)), attitude()});
  }
  return truth;
}

inline core::Trajectory estimateTrajectory() {
  core::Trajectory estimates;
  for (int j = 0; j < kEstimates; ++j) {
    const double t = estimateStamp(j);
    estimates.push_back({t, truthPosition(t) + kOffset, attitude()});
  }
  return estimates;
}

// A fresh, empty directory under the test's temporary directory, named after the
// running test too: ctest runs the tests of one binary as parallel processes.
inline std::filesystem::path freshDir(const std::string& name) {
  std::string test_name;
  if (const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info()) {
    test_name.append(info->test_suite_name()).append("_").append(info->name()).append("_");
  }
  const std::filesystem::path dir =
      std::filesystem::path(::testing::TempDir()) / ("nadir_gui_" + test_name + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// truth.tum and vo_test.tum, no log, no metrics.json.
inline std::filesystem::path writeTumRun(const std::string& name) {
  const std::filesystem::path dir = freshDir(name);
  core::writeTum((dir / "truth.tum").string(), truthTrajectory());
  core::writeTum((dir / "vo_test.tum").string(), estimateTrajectory());
  return dir;
}

inline nadir::pose_t poseMessage(double t_s, const Eigen::Vector3d& p,
                                 const Eigen::Quaterniond& q) {
  nadir::pose_t msg{};
  msg.utime = static_cast<std::int64_t>(std::llround(t_s * 1e6));
  for (int i = 0; i < 3; ++i) msg.pos[i] = p[i];
  core::quaternionToWire(q, msg.orientation);
  return msg;
}

template <class Msg>
void writeMessage(core::LcmLogWriter& writer, const std::string& channel, const Msg& msg) {
  const std::vector<std::uint8_t> bytes = ::nadir::test::encodeMessage(msg);
  writer.write(msg.utime, channel, bytes.data(), bytes.size());
}

// The tiny run as `nadir run` records it (run.lcmlog: the truth on POSE_TRUTH and
// the estimates as source vo_feature), with the fifth estimate LOST.
inline constexpr int kLostEstimate = 4;
inline std::filesystem::path writeLogRun(const std::string& name) {
  const std::filesystem::path dir = freshDir(name);
  core::LcmLogWriter writer((dir / "run.lcmlog").string());
  for (const core::StampedPose& pose : truthTrajectory()) {
    writeMessage(writer, "POSE_TRUTH", poseMessage(pose.t_s, pose.p_ned_m, pose.q_world_body));
  }
  const core::Trajectory estimates = estimateTrajectory();
  for (int j = 0; j < kEstimates; ++j) {
    const core::StampedPose& pose = estimates[static_cast<std::size_t>(j)];
    nadir::vo_estimate_t msg{};
    msg.utime = poseMessage(pose.t_s, pose.p_ned_m, pose.q_world_body).utime;
    msg.source = "vo_feature";
    msg.status = j == kLostEstimate ? logs::SourceEstimate::kLost : logs::SourceEstimate::kTracking;
    msg.pose = poseMessage(pose.t_s, pose.p_ned_m, pose.q_world_body);
    writeMessage(writer, "POSE_VO_FEATURE", msg);
  }
  return dir;
}

}  // namespace nadir::gui::test
