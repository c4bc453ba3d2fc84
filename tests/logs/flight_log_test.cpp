// A flight read out of an LCM log as truth: pose_t, or NAV_POSITION paired with
// NAV_ATTITUDE by SLERP; sorting, repeats, damage and foreign files.

#include "logs/flight_log.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/frames.h"
#include "core/lcm_log.h"
#include "nadir/attitude_t.hpp"
#include "nadir/geodetic_position_t.hpp"
#include "nadir/imu_t.hpp"
#include "nadir/pose_t.hpp"

namespace nadir::logs {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + "nadir_flight_log_" + name;
}

template <typename Msg>
void writeMessage(core::LcmLogWriter& log, std::int64_t timestamp_utime, const std::string& channel,
                  const Msg& message) {
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(message.getEncodedSize()));
  ASSERT_EQ(message.encode(bytes.data(), 0, static_cast<int>(bytes.size())),
            static_cast<int>(bytes.size()));
  log.write(timestamp_utime, channel, bytes.data(), bytes.size());
}

struct State {
  std::int64_t utime = 0;
  Eigen::Vector3d p_ned_m;
  Eigen::Quaterniond q_world_body;
};

// A pose with distinct fields and a general (non-axis) attitude.
State makeState(std::int64_t utime, double base) {
  return {utime, Eigen::Vector3d(base + 10.5, -(base + 20.25), -(base + 120.125)),
          core::quaternionFromRpy({(5.0 + base) * kDeg, -3.0 * kDeg, 40.0 * kDeg})};
}

nadir::pose_t poseMessage(const State& state) {
  nadir::pose_t pose{};
  pose.utime = state.utime;
  for (int i = 0; i < 3; ++i) pose.pos[i] = state.p_ned_m[i];
  core::quaternionToWire(state.q_world_body, pose.orientation);
  return pose;
}

nadir::geodetic_position_t positionMessage(const State& state, const core::LocalNedFrame& frame) {
  const core::Geodetic point = frame.geodeticFromNed(state.p_ned_m);
  nadir::geodetic_position_t position{};
  position.utime = state.utime;
  position.latitude_rad = point.lat_rad;
  position.longitude_rad = point.lon_rad;
  position.altitude_m = point.alt_m;
  return position;
}

nadir::attitude_t attitudeMessage(const State& state) {
  nadir::attitude_t attitude{};
  attitude.utime = state.utime;
  core::quaternionToWire(state.q_world_body, attitude.orientation);
  return attitude;
}

// Textbook SLERP on the coefficients: (sin((1-s)t) qa + sin(s t) qb) / sin(t), cos(t) = qa.qb > 0.
Eigen::Quaterniond handSlerp(const Eigen::Quaterniond& qa, const Eigen::Quaterniond& qb, double s) {
  const double theta = std::acos(qa.dot(qb));
  const double wa = std::sin((1.0 - s) * theta) / std::sin(theta);
  const double wb = std::sin(s * theta) / std::sin(theta);
  return Eigen::Quaterniond(wa * qa.w() + wb * qb.w(), wa * qa.x() + wb * qb.x(),
                            wa * qa.y() + wb * qb.y(), wa * qa.z() + wb * qb.z());
}

double angleBetween(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return Eigen::AngleAxisd(a.conjugate() * b).angle();
}

// pose_t on POSE_TRUTH reads back as the same poses at the messages' utime; bad ones skipped.
TEST(FlightLog, PoseTruthReadsBackExactly) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(37.3, -113.0, 1500.0));
  const std::string path = tempPath("pose_truth.lcmlog");
  std::vector<State> states;
  {
    core::LcmLogWriter log(path);
    for (int i = 0; i < 6; ++i) {
      states.push_back(makeState(1'000'000 + 100'000 * i, i));
      writeMessage(log, 42 + i, "POSE_TRUTH", poseMessage(states.back()));
      writeMessage(log, 42 + i, "NAV_POSITION", positionMessage(states.back(), frame));
      writeMessage(log, 42 + i, "NAV_ATTITUDE", attitudeMessage(states.back()));
    }
    nadir::pose_t not_finite = poseMessage(makeState(1'050'000, 9.0));
    not_finite.pos[0] = std::numeric_limits<double>::infinity();
    writeMessage(log, 0, "POSE_TRUTH", not_finite);
  }
  FlightLogStats stats;
  const core::Trajectory trajectory = readFlightLog(path, {}, frame, &stats);
  EXPECT_TRUE(stats.from_pose_channel);
  EXPECT_EQ(stats.poses, 6);
  EXPECT_EQ(stats.decode_failures, 0);
  EXPECT_EQ(stats.invalid_messages, 1);
  EXPECT_TRUE(stats.damage.empty()) << stats.damage;
  ASSERT_EQ(trajectory.size(), states.size());
  for (std::size_t i = 0; i < states.size(); ++i) {
    const core::StampedPose& pose = trajectory[i];
    EXPECT_EQ(pose.t_s, static_cast<double>(states[i].utime) / 1e6);
    EXPECT_EQ(pose.p_ned_m, states[i].p_ned_m);
    EXPECT_NEAR((pose.q_world_body.coeffs() - states[i].q_world_body.coeffs()).norm(), 0.0, 1e-15);
  }
}

// Out-of-order poses are sorted, exact repeats dropped; two different poses at one time throw.
TEST(FlightLog, SortsDropsDuplicatesAndRefusesConflicts) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(37.3, -113.0, 1500.0));
  const std::string path = tempPath("unordered.lcmlog");
  {
    core::LcmLogWriter log(path);
    for (int i : {2, 0, 1, 1, 3}) {
      writeMessage(log, 0, "POSE_TRUTH", poseMessage(makeState(1'000'000 * i, i)));
    }
  }
  FlightLogStats stats;
  const core::Trajectory trajectory = readFlightLog(path, {}, frame, &stats);
  EXPECT_EQ(stats.duplicates, 1);
  ASSERT_EQ(trajectory.size(), 4u);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(trajectory[i].t_s, static_cast<double>(i));

  const std::string conflict = tempPath("conflict.lcmlog");
  {
    core::LcmLogWriter log(conflict);
    writeMessage(log, 0, "POSE_TRUTH", poseMessage(makeState(0, 0)));
    writeMessage(log, 0, "POSE_TRUTH", poseMessage(makeState(1'000'000, 1)));
    writeMessage(log, 0, "POSE_TRUTH", poseMessage(makeState(1'000'000, 2)));
  }
  try {
    readFlightLog(conflict, {}, frame);
    FAIL() << "two different poses at one time were accepted";
  } catch (const core::TrajectoryError& e) {
    EXPECT_NE(std::string(e.what()).find(conflict), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not increasing"), std::string::npos) << e.what();
  }
}

// 4 Hz positions + 10 Hz attitudes give poses at the position times with SLERPed attitudes.
TEST(FlightLog, NavPositionAndAttitudeArePairedBySlerp) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(37.3, -113.0, 1500.0));
  const std::string path = tempPath("nav.lcmlog");
  const auto attitudeAt = [](int k) {  // 10 Hz, k = 0..10; roll, pitch and yaw all change
    return core::quaternionFromRpy(
        {(10.0 + 4.0 * k) * kDeg, (5.0 - 3.0 * k) * kDeg, (30.0 + 20.0 * k) * kDeg});
  };
  const auto positionAt = [](std::int64_t utime) {
    const double t_s = static_cast<double>(utime) * 1e-6;
    return Eigen::Vector3d(25.0 * t_s, 300.0 + 5.0 * t_s * t_s, -120.0 - 2.0 * t_s);
  };
  const std::int64_t t0 = 1'700'000'000'000'000;
  {
    core::LcmLogWriter log(path);
    for (int k = 0; k <= 10; ++k) {
      nadir::attitude_t attitude{};
      attitude.utime = t0 + 100'000 * k;
      core::quaternionToWire(attitudeAt(k), attitude.orientation);
      writeMessage(log, attitude.utime + 777, "FC_ATTITUDE", attitude);
    }
    // Positions at 4 Hz from -0.1 s: the first (before) and the last (after) are outside.
    for (int j = 0; j < 6; ++j) {
      const std::int64_t offset = -100'000 + 250'000 * j;
      nadir::geodetic_position_t position{};
      position.utime = t0 + offset;
      const core::Geodetic point = frame.geodeticFromNed(positionAt(offset));
      position.latitude_rad = point.lat_rad;
      position.longitude_rad = point.lon_rad;
      position.altitude_m = point.alt_m;
      position.altitude_rel_m = -9999.0;  // Not used: altitude_m is.
      writeMessage(log, position.utime + 555, "FC_POSITION", position);
    }
    const std::uint8_t garbage[] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
    log.write(t0, "FC_POSITION", garbage, sizeof garbage);
    nadir::imu_t imu{};
    writeMessage(log, t0, "IMU", imu);
  }
  FlightLogChannels channels;
  channels.position_channel = "FC_POSITION";
  channels.attitude_channel = "FC_ATTITUDE";
  FlightLogStats stats;
  const core::Trajectory trajectory = readFlightLog(path, channels, frame, &stats);
  EXPECT_FALSE(stats.from_pose_channel);
  EXPECT_EQ(stats.decode_failures, 1);
  EXPECT_EQ(stats.positions_outside_attitude_span, 2);

  const std::vector<std::int64_t> offsets = {150'000, 400'000, 650'000, 900'000};
  ASSERT_EQ(trajectory.size(), offsets.size());
  for (std::size_t i = 0; i < offsets.size(); ++i) {
    const core::StampedPose& pose = trajectory[i];
    EXPECT_EQ(pose.t_s, static_cast<double>(t0 + offsets[i]) / 1e6);
    EXPECT_NEAR((pose.p_ned_m - positionAt(offsets[i])).norm(), 0.0, 1e-6);
  }
  // 0.65 s lies halfway between the attitudes at 0.6 s and 0.7 s.
  const Eigen::Quaterniond expected = handSlerp(attitudeAt(6), attitudeAt(7), 0.5);
  EXPECT_NEAR(angleBetween(trajectory[2].q_world_body, expected), 0.0, 1e-12);
  // 0.4 s is exactly an attitude sample; 0.15 s is halfway between 0.1 s and 0.2 s.
  EXPECT_NEAR(angleBetween(trajectory[1].q_world_body, attitudeAt(4)), 0.0, 1e-12);
  EXPECT_NEAR(
      angleBetween(trajectory[0].q_world_body, handSlerp(attitudeAt(1), attitudeAt(2), 0.5)), 0.0,
      1e-12);
}

// A log with neither pose_t nor position/attitude pairs throws, naming file and channels.
TEST(FlightLog, LogWithNeitherIsRefused) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(37.3, -113.0, 1500.0));
  const std::string path = tempPath("imu_only.lcmlog");
  {
    core::LcmLogWriter log(path);
    nadir::imu_t imu{};
    for (int i = 0; i < 3; ++i) writeMessage(log, i, "IMU", imu);
    // Positions without any attitude make no pairs either.
    writeMessage(log, 5, "NAV_POSITION", positionMessage(makeState(5, 0), frame));
  }
  try {
    readFlightLog(path, {}, frame);
    FAIL() << "a log without truth was accepted";
  } catch (const core::TrajectoryError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  path + " has no pose_t on POSE_TRUTH and no NAV_POSITION/NAV_ATTITUDE pairs"),
              std::string::npos)
        << e.what();
  }
}

// A file that is not an LCM log, and a missing file, are errors naming the file.
TEST(FlightLog, NonLogFileIsRefused) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(37.3, -113.0, 1500.0));
  const std::string path = tempPath("not_a_log.csv");
  std::ofstream(path) << "time_s,lat_deg,lon_deg\n0,37.3,-113.0\n";
  try {
    readFlightLog(path, {}, frame);
    FAIL() << "a CSV file was read as an LCM log";
  } catch (const core::TrajectoryError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not an LCM log"), std::string::npos) << e.what();
  }
  const std::string missing = tempPath("does_not_exist.lcmlog");
  try {
    readFlightLog(missing, {}, frame);
    FAIL() << "a missing file was accepted";
  } catch (const core::TrajectoryError& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
}

// A log cut inside its last event gives the poses before the cut and reports the truncation.
TEST(FlightLog, TruncatedLogKeepsWhatWasRead) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(37.3, -113.0, 1500.0));
  const std::string path = tempPath("truncated.lcmlog");
  {
    core::LcmLogWriter log(path);
    for (int i = 0; i < 5; ++i) {
      writeMessage(log, i, "POSE_TRUTH", poseMessage(makeState(1'000'000 * i, i)));
    }
  }
  const auto size = std::filesystem::file_size(path);
  std::filesystem::resize_file(path, size - 40);
  FlightLogStats stats;
  const core::Trajectory trajectory = readFlightLog(path, {}, frame, &stats);
  ASSERT_EQ(trajectory.size(), 4u);
  EXPECT_EQ(trajectory.back().t_s, 3.0);
  EXPECT_NE(stats.damage.find("truncated"), std::string::npos) << stats.damage;
}

}  // namespace
}  // namespace nadir::logs
