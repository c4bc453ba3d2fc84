// Reading a run out of an LCM log (core's LcmLogWriter): the truth and the
// estimates with their utimes, sources by name, damage, and the truth's channel.

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "core/frames.h"
#include "core/lcm_log.h"
#include "logs/eval/run_metrics.h"
#include "logs/run_log.h"
#include "nadir/nav_state_t.hpp"
#include "nadir/pose_t.hpp"
#include "nadir/vo_estimate_t.hpp"

namespace nadir::logs {
namespace {

std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + "nadir_run_log_" + name;
}

nadir::pose_t truthMessage(std::int64_t utime, const Eigen::Vector3d& p,
                           const Eigen::Quaterniond& q) {
  nadir::pose_t msg{};
  msg.utime = utime;
  for (int i = 0; i < 3; ++i) msg.pos[i] = p[i];
  core::quaternionToWire(q, msg.orientation);
  return msg;
}

nadir::vo_estimate_t estimateMessage(std::int64_t utime, const std::string& source, int status,
                                     const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  nadir::vo_estimate_t msg{};
  msg.utime = utime;
  msg.source = source;
  msg.status = static_cast<std::int8_t>(status);
  msg.pose = truthMessage(utime, p, q);
  if (status != SourceEstimate::kTracking) {
    for (double& w : msg.pose.orientation) w = 0;  // not meaningful: must not be refused
  }
  return msg;
}

template <class Msg>
void writeMessage(core::LcmLogWriter& writer, std::int64_t event_utime, const std::string& channel,
                  const Msg& msg) {
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  writer.write(event_utime, channel, bytes.data(), bytes.size());
}

constexpr std::int64_t kStart = 1'700'000'000'000'000;  // UNIX-time utimes, as a live run

// Truth 100 Hz for 2 s; vo_feature 10 Hz (2 INITIALIZING then TRACKING); one ppa; noise.
std::string writeSampleLog(const std::string& name) {
  const std::string path = tempPath(name);
  core::LcmLogWriter writer(path);
  const Eigen::Quaterniond yaw90(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ()));
  for (int k = 0; k <= 200; ++k) {
    const std::int64_t utime = kStart + k * 10'000;
    // The event stamp differs from the message utime: the message's wins.
    writeMessage(writer, utime + 777, "POSE_TRUTH",
                 truthMessage(utime, Eigen::Vector3d(0.2 * k, 1, -50), yaw90));
    if (k % 10 == 5) {
      const int frame = k / 10;
      writeMessage(
          writer, utime + 777, "POSE_VO_FEATURE",
          estimateMessage(utime, "vo_feature",
                          frame < 2 ? SourceEstimate::kInitializing : SourceEstimate::kTracking,
                          Eigen::Vector3d(0.2 * k + 1.0, 1, -50), yaw90));
    }
    if (k == 100) {
      writeMessage(writer, utime, "POSE_PPA",
                   estimateMessage(utime, "ppa", SourceEstimate::kLost, Eigen::Vector3d::Zero(),
                                   Eigen::Quaterniond::Identity()));
      const std::uint8_t garbage[5] = {1, 2, 3, 4, 5};
      writer.write(utime, "POSE_TRUTH", garbage, sizeof garbage);
      writer.write(utime, "IMU", garbage, sizeof garbage);
    }
  }
  return path;
}

// A navigation filter's nav_state_t is gathered by its source name with its
// covariances and the last GPS fix, and its metrics get the filter's figures;
// one with an asymmetric covariance is left out and counted as damage.
TEST(RunLog, FilterStatesAreGatheredAndEvaluated) {
  const std::string path = tempPath("filter");
  {
    core::LcmLogWriter writer(path);
    for (int k = 0; k <= 200; ++k) {
      const std::int64_t utime = kStart + k * 10'000;
      writeMessage(
          writer, utime, "POSE_TRUTH",
          truthMessage(utime, Eigen::Vector3d(0.2 * k, 1, -50), Eigen::Quaterniond::Identity()));
      if (k % 10 != 0) continue;
      writeMessage(
          writer, utime, "POSE_NAV",
          estimateMessage(utime, "nav", SourceEstimate::kTracking, Eigen::Vector3d(0.2 * k, 1, -50),
                          Eigen::Quaterniond::Identity()));
      nadir::nav_state_t state{};
      state.utime = utime;
      state.source = "nav";
      state.pose = truthMessage(utime, Eigen::Vector3d(0.2 * k + 0.1, 1, -50),
                                Eigen::Quaterniond::Identity());
      for (int i : {0, 4, 8}) {
        state.position_covariance_m2[i] = 0.01;
        state.velocity_covariance_m2ps2[i] = 0.01;
        state.attitude_covariance_rad2[i] = 1e-4;
      }
      state.vo_scale = 1.0;
      state.last_gps_utime = kStart;
      if (k == 100) state.position_covariance_m2[1] = 0.5;  // not symmetric
      writeMessage(writer, utime, "POSE_NAV_STATE", state);
    }
  }
  const LogTrajectories run = readRunLog(path);
  ASSERT_EQ(run.filters.count("nav"), 1u);
  const std::vector<FilterState>& states = run.filters.at("nav");
  ASSERT_EQ(states.size(), 20u);
  EXPECT_NEAR(states.front().last_gps_t_s, core::stampFromUtime(kStart), 1e-6);
  EXPECT_EQ(states.front().position_covariance_m2(1, 1), 0.01);
  EXPECT_NE(run.damage.find("1 undecodable or invalid message on POSE_NAV_STATE"),
            std::string::npos)
      << run.damage;
  const eval::RunMetrics metrics =
      eval::evaluate(run.truth, run.sources, eval::EvalOptions{}, run.filters);
  ASSERT_TRUE(metrics.sources.at("nav").filter.has_value());
  // 0.1 m north against a variance of 0.01 m^2: NEES 1 at every state.
  EXPECT_NEAR(metrics.sources.at("nav").filter->nees_position_mean, 1.0, 1e-9);
  EXPECT_NEAR(metrics.sources.at("nav").filter->denial_s, 0.0, 1e-9);
}

// readRunLog takes truth and estimates with their utimes, names sources by their
// source field, and reports the undecodable message on the truth's channel as damage.
TEST(RunLog, ReadsTruthAndEstimatesFromLcmLogWriterLog) {
  const LogTrajectories log = readRunLog(writeSampleLog("run.lcmlog"), "POSE_TRUTH");
  ASSERT_EQ(log.truth.size(), 201u);
  EXPECT_DOUBLE_EQ(log.truth.front().t_s, 1'700'000'000.0);
  EXPECT_NEAR(log.truth.back().t_s - log.truth.front().t_s, 2.0, 1e-6);
  EXPECT_NEAR((log.truth[10].p_ned_m - Eigen::Vector3d(2, 1, -50)).norm(), 0, 1e-12);
  EXPECT_NEAR(core::rpyFromQuaternion(log.truth[10].q_world_body).yaw_rad, std::numbers::pi / 2,
              1e-12);
  ASSERT_EQ(log.sources.size(), 2u);
  const auto& feature = log.sources.at("vo_feature");
  ASSERT_EQ(feature.size(), 20u);
  EXPECT_EQ(feature[0].status, SourceEstimate::kInitializing);
  EXPECT_EQ(feature[2].status, SourceEstimate::kTracking);
  EXPECT_NEAR(feature[2].t_s - log.truth.front().t_s, 0.25, 1e-6);
  ASSERT_EQ(log.sources.at("ppa").size(), 1u);
  EXPECT_EQ(log.sources.at("ppa")[0].status, SourceEstimate::kLost);
  EXPECT_NE(log.damage.find("1 undecodable or invalid message on POSE_TRUTH"), std::string::npos)
      << log.damage;

  // Every TRACKING estimate is 1 m north of the truth.
  const eval::RunMetrics run = eval::evaluate(log.truth, log.sources, eval::EvalOptions{});
  const eval::SourceMetrics& m = run.sources.at("vo_feature");
  EXPECT_NEAR(m.position_rmse_m, 1.0, 1e-6);
  EXPECT_NEAR(m.rotation_rmse_deg, 0.0, 1e-6);
  EXPECT_NEAR(m.tracked_pct, 100.0 * 1.75 / 2.0, 1e-6);  // TRACKING from 0.25 s to the end, 2.0 s
  EXPECT_NEAR(run.truth_track_length_m, 40.0, 1e-9);
  EXPECT_FALSE(run.sources.at("ppa").initialised);

  // Without the truth's channel named, the one channel carrying pose_t is the truth;
  // the garbage there (not a pose_t) is no message of the run's.
  const LogTrajectories found = readRunLog(tempPath("run.lcmlog"));
  EXPECT_EQ(found.truth_channel, "POSE_TRUTH");
  EXPECT_EQ(found.truth.size(), 201u);
  EXPECT_EQ(found.sources.size(), 2u);
  EXPECT_TRUE(found.damage.empty()) << found.damage;
}

// An estimate is found by its type on any channel and keeps its source's name.
TEST(RunLog, EstimatesOnRenamedChannelsKeepTheirSource) {
  const std::string path = tempPath("renamed.lcmlog");
  {
    core::LcmLogWriter writer(path);
    for (int k = 0; k <= 10; ++k) {
      const std::int64_t utime = kStart + k * 100'000;
      writeMessage(writer, utime, "TRUTH_2",
                   truthMessage(utime, Eigen::Vector3d(k, 0, -50), Eigen::Quaterniond::Identity()));
      writeMessage(writer, utime, "MY_PPA",
                   estimateMessage(utime, "ppa", SourceEstimate::kTracking,
                                   Eigen::Vector3d(k, 1, -50), Eigen::Quaterniond::Identity()));
    }
  }
  const LogTrajectories log = readRunLog(path);
  EXPECT_EQ(log.truth_channel, "TRUTH_2");
  ASSERT_EQ(log.sources.size(), 1u);
  EXPECT_EQ(log.sources.begin()->first, "ppa");
  EXPECT_EQ(log.sources.at("ppa").size(), 11u);
}

// pose_t on two channels: which one is the truth must be said.
TEST(RunLog, TwoPoseChannelsNeedTheTruthNamed) {
  const std::string path = tempPath("two_poses.lcmlog");
  {
    core::LcmLogWriter writer(path);
    for (const char* channel : {"POSE_TRUTH", "POSE_OTHER"}) {
      writeMessage(writer, kStart, channel,
                   truthMessage(kStart, Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity()));
    }
  }
  try {
    readRunLog(path);
    FAIL() << "two pose_t channels were taken without a truth named";
  } catch (const RunLogError& error) {
    EXPECT_NE(std::string(error.what()).find("POSE_OTHER, POSE_TRUTH"), std::string::npos)
        << error.what();
  }
  EXPECT_EQ(readRunLog(path, "POSE_OTHER").truth_channel, "POSE_OTHER");
}

// A truncated log gives what was read and the reader's damage report.
TEST(RunLog, TruncatedLogReportsDamage) {
  const std::string path = writeSampleLog("truncated.lcmlog");
  std::filesystem::resize_file(path, std::filesystem::file_size(path) - 20);
  const LogTrajectories log = readRunLog(path);
  EXPECT_EQ(log.truth.size(), 200u);  // the last truth event was cut
  EXPECT_FALSE(log.damage.empty());
}

// An empty log, a log without truth and a missing file are errors naming the file.
TEST(RunLog, EmptyOrTruthlessLogIsAnError) {
  const std::string empty = tempPath("empty.lcmlog");
  { core::LcmLogWriter writer(empty); }
  try {
    readRunLog(empty);
    FAIL();
  } catch (const RunLogError& error) {
    EXPECT_NE(std::string(error.what()).find(empty + ": the log is empty"), std::string::npos)
        << error.what();
  }
  const std::string no_truth = tempPath("no_truth.lcmlog");
  {
    core::LcmLogWriter writer(no_truth);
    writeMessage(writer, kStart, "POSE_PPA",
                 estimateMessage(kStart, "ppa", SourceEstimate::kLost, Eigen::Vector3d::Zero(),
                                 Eigen::Quaterniond::Identity()));
  }
  try {
    readRunLog(no_truth);
    FAIL();
  } catch (const RunLogError& error) {
    EXPECT_NE(std::string(error.what()).find("no truth"), std::string::npos) << error.what();
  }
  EXPECT_THROW(readRunLog(tempPath("does_not_exist.lcmlog")), RunLogError);
}

}  // namespace
}  // namespace nadir::logs
