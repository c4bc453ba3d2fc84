// Simulator structs <-> LCM messages, the NAV_* truth split, and flight logs read as truth.

#include "nodes/sim/sim_messages.h"

#include <gtest/gtest.h>
#include <GeographicLib/LocalCartesian.hpp>

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
#include "nadir/imu_t.hpp"

namespace nadir::sim {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + "nadir_sim_messages_" + name;
}

template <typename Msg>
void writeMessage(core::LcmLogWriter& log, std::int64_t timestamp_utime, const std::string& channel,
                  const Msg& message) {
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(message.getEncodedSize()));
  ASSERT_EQ(message.encode(bytes.data(), 0, static_cast<int>(bytes.size())),
            static_cast<int>(bytes.size()));
  log.write(timestamp_utime, channel, bytes.data(), bytes.size());
}

// A state with every field set and distinct, with a general (non-axis) attitude.
VehicleState makeState(std::int64_t utime, double base) {
  VehicleState state;
  state.utime = utime;
  state.p_ned_m = Eigen::Vector3d(base + 10.5, -(base + 20.25), -(base + 120.125));
  state.v_ned_mps = Eigen::Vector3d(base + 1.5, base - 2.25, 0.375);
  state.a_ned_mps2 = Eigen::Vector3d(0.125, -0.25, base * 0.01);
  state.q_world_body = core::quaternionFromRpy({(5.0 + base) * kDeg, -3.0 * kDeg, 40.0 * kDeg});
  state.omega_body_rps = Eigen::Vector3d(0.01, -0.02, 0.03 + base * 1e-3);
  return state;
}

void expectStateEq(const VehicleState& expected, const VehicleState& actual) {
  EXPECT_EQ(actual.utime, expected.utime);
  EXPECT_EQ(actual.p_ned_m, expected.p_ned_m);
  EXPECT_EQ(actual.v_ned_mps, expected.v_ned_mps);
  EXPECT_EQ(actual.a_ned_mps2, expected.a_ned_mps2);
  EXPECT_EQ(actual.q_world_body.coeffs(), expected.q_world_body.coeffs());
  EXPECT_EQ(actual.omega_body_rps, expected.omega_body_rps);
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

// ---------------------------------------------------------------- pressure and sensors

// ISA pressure matches the standard-atmosphere table at 0, 1, 5, 11 and 20 km within 1 Pa.
TEST(SimMessages, StandardAtmosphereMatchesIsaTable) {
  EXPECT_NEAR(standardAtmospherePressure_pa(0.0), 101325.0, 1.0);
  EXPECT_NEAR(standardAtmospherePressure_pa(1000.0), 89874.6, 1.0);
  EXPECT_NEAR(standardAtmospherePressure_pa(5000.0), 54019.9, 1.0);
  EXPECT_NEAR(standardAtmospherePressure_pa(11000.0), 22632.1, 1.0);
  EXPECT_NEAR(standardAtmospherePressure_pa(20000.0), 5474.89, 1.0);
  // Continuous across the tropopause: both layers agree just above and below 11 km.
  EXPECT_NEAR(standardAtmospherePressure_pa(11000.001), standardAtmospherePressure_pa(11000.0),
              0.1);
}

// baro_t carries the sample's time and altitude and the ISA pressure at that altitude.
TEST(SimMessages, BaroMessageCarriesAltitudeAndIsaPressure) {
  const nadir::baro_t baro = toBaroMessage({.utime = 123456, .altitude_m = 1000.0});
  EXPECT_EQ(baro.utime, 123456);
  EXPECT_EQ(baro.altitude_m, 1000.0);
  EXPECT_NEAR(baro.pressure_pa, 89874.6, 1.0);
}

// imu_t, range_t and gps_t carry every field of their samples, with the enums mapped.
TEST(SimMessages, SensorMessagesCarryEveryField) {
  ImuSample imu_sample;
  imu_sample.utime = 7;
  imu_sample.angular_velocity_rps = Eigen::Vector3d(0.1, -0.2, 0.3);
  imu_sample.linear_acceleration_mps2 = Eigen::Vector3d(0.5, 0.25, -9.80665);
  const nadir::imu_t imu = toImuMessage(imu_sample);
  EXPECT_EQ(imu.utime, 7);
  EXPECT_EQ(imu.angular_velocity_rps[1], -0.2);
  EXPECT_EQ(imu.angular_velocity_rps[2], 0.3);
  EXPECT_EQ(imu.linear_acceleration_mps2[0], 0.5);
  EXPECT_EQ(imu.linear_acceleration_mps2[2], -9.80665);

  RangeSample range_sample;
  range_sample.utime = 8;
  range_sample.range_m = 42.5;
  range_sample.status = RangeStatus::TOO_CLOSE;
  range_sample.direction_body = Eigen::Vector3d(0.6, 0.0, 0.8);
  const nadir::range_t range = toRangeMessage(range_sample, 0.1, 100.0);
  EXPECT_EQ(range.utime, 8);
  EXPECT_EQ(range.range_m, 42.5);
  EXPECT_EQ(range.min_range_m, 0.1);
  EXPECT_EQ(range.max_range_m, 100.0);
  EXPECT_EQ(range.direction_body[0], 0.6);
  EXPECT_EQ(range.direction_body[2], 0.8);
  EXPECT_EQ(range.status, std::int8_t{nadir::range_t::STATUS_TOO_CLOSE});
  range_sample.status = RangeStatus::VALID;
  EXPECT_EQ(toRangeMessage(range_sample, 0.1, 100.0).status,
            std::int8_t{nadir::range_t::STATUS_VALID});
  range_sample.status = RangeStatus::OUT_OF_RANGE;
  EXPECT_EQ(toRangeMessage(range_sample, 0.1, 100.0).status,
            std::int8_t{nadir::range_t::STATUS_OUT_OF_RANGE});

  GpsSample gps_sample;
  gps_sample.utime = 9;
  gps_sample.lat_rad = 0.65;
  gps_sample.lon_rad = -1.97;
  gps_sample.alt_m = 1520.5;
  gps_sample.velocity_ned_mps = Eigen::Vector3d(20.0, -1.0, 0.5);
  gps_sample.horizontal_accuracy_m = 1.5;
  gps_sample.vertical_accuracy_m = 3.0;
  gps_sample.num_satellites = 12;
  gps_sample.fix = GpsFix::FIX_3D;
  const nadir::gps_t gps = toGpsMessage(gps_sample);
  EXPECT_EQ(gps.utime, 9);
  EXPECT_EQ(gps.latitude_rad, 0.65);
  EXPECT_EQ(gps.longitude_rad, -1.97);
  EXPECT_EQ(gps.altitude_m, 1520.5);
  EXPECT_EQ(gps.velocity_ned_mps[0], 20.0);
  EXPECT_EQ(gps.velocity_ned_mps[2], 0.5);
  EXPECT_EQ(gps.horizontal_accuracy_m, 1.5);
  EXPECT_EQ(gps.vertical_accuracy_m, 3.0);
  EXPECT_EQ(gps.num_satellites, 12);
  EXPECT_EQ(gps.fix_type, std::int8_t{nadir::gps_t::FIX_3D});
  EXPECT_EQ(toGpsMessage(GpsSample{}).fix_type, std::int8_t{nadir::gps_t::FIX_NONE});
}

// ---------------------------------------------------------------- pose

// State -> pose_t -> state is exact, and the wire quaternion is w first.
TEST(SimMessages, PoseRoundTripIsExact) {
  const VehicleState state = makeState(1'700'000'000'123'457, 3.0);
  const nadir::pose_t pose = toPoseMessage(state);
  EXPECT_EQ(pose.utime, state.utime);
  EXPECT_EQ(pose.pos[2], state.p_ned_m.z());
  EXPECT_EQ(pose.vel[1], state.v_ned_mps.y());
  EXPECT_EQ(pose.accel[2], state.a_ned_mps2.z());
  EXPECT_EQ(pose.rotation_rate[2], state.omega_body_rps.z());
  EXPECT_EQ(pose.orientation[0], state.q_world_body.w());
  EXPECT_EQ(pose.orientation[3], state.q_world_body.z());
  expectStateEq(state, stateFromPoseMessage(pose));
}

// Non-finite fields and quaternions off unit norm by > 1e-3 are refused; < 1e-3 is normalised.
TEST(SimMessages, InvalidPoseIsRefused) {
  const nadir::pose_t good = toPoseMessage(makeState(5, 1.0));

  nadir::pose_t bad = good;
  bad.pos[1] = std::numeric_limits<double>::quiet_NaN();
  try {
    stateFromPoseMessage(bad);
    FAIL() << "a NaN position was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("pos[1]"), std::string::npos) << e.what();
  }
  bad = good;
  bad.accel[0] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(stateFromPoseMessage(bad), std::invalid_argument);
  bad = good;
  bad.orientation[2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(stateFromPoseMessage(bad), std::invalid_argument);

  bad = good;
  for (double& c : bad.orientation) c *= 1.002;
  try {
    stateFromPoseMessage(bad);
    FAIL() << "a quaternion of norm 1.002 was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("orientation"), std::string::npos) << e.what();
  }

  nadir::pose_t nearly = good;
  for (double& c : nearly.orientation) c *= 1.0005;
  const VehicleState state = stateFromPoseMessage(nearly);
  EXPECT_NEAR(state.q_world_body.norm(), 1.0, 1e-15);
  EXPECT_NEAR(state.q_world_body.w(), good.orientation[0], 1e-15);
}

// ---------------------------------------------------------------- NAV_* split

// Level heading east: yaw 90 deg, q = (cos45, 0, 0, sin45); rates in deg/s; velocity in NED.
TEST(SimMessages, NavAttitudeRatesAndVelocity) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(47.0, 8.0, 400.0));
  VehicleState state;
  state.utime = 2'000'000;
  state.q_world_body =
      Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ()));
  state.v_ned_mps = Eigen::Vector3d(0.5, 20.0, -1.0);
  state.omega_body_rps = Eigen::Vector3d(std::numbers::pi / 4, -std::numbers::pi / 180, 0.5);
  const NavMessages nav = toNavMessages(state, frame, 400.0);

  EXPECT_EQ(nav.attitude.utime, 2'000'000);
  EXPECT_NEAR(nav.attitude.yaw_rad, 90.0 * kDeg, 1e-12);
  EXPECT_NEAR(nav.attitude.pitch_rad, 0.0, 1e-12);
  EXPECT_NEAR(nav.attitude.roll_rad, 0.0, 1e-12);
  const double c45 = std::sqrt(0.5);
  EXPECT_NEAR(nav.attitude.orientation[0], c45, 1e-15);
  EXPECT_NEAR(nav.attitude.orientation[1], 0.0, 1e-15);
  EXPECT_NEAR(nav.attitude.orientation[2], 0.0, 1e-15);
  EXPECT_NEAR(nav.attitude.orientation[3], c45, 1e-15);

  EXPECT_EQ(nav.rates.utime, 2'000'000);
  EXPECT_NEAR(nav.rates.angular_velocity_dps[0], 45.0, 1e-12);
  EXPECT_NEAR(nav.rates.angular_velocity_dps[1], -1.0, 1e-12);
  EXPECT_NEAR(nav.rates.angular_velocity_dps[2], 28.64788975654116, 1e-12);  // 0.5 rad/s

  EXPECT_EQ(nav.velocity.utime, 2'000'000);
  EXPECT_EQ(nav.velocity.velocity_ned_mps[0], 0.5);
  EXPECT_EQ(nav.velocity.velocity_ned_mps[1], 20.0);
  EXPECT_EQ(nav.velocity.velocity_ned_mps[2], -1.0);
  EXPECT_EQ(nav.position.utime, 2'000'000);
}

// Roll, pitch and yaw in attitude_t are the Z-Y-X angles the quaternion was built from.
TEST(SimMessages, NavAttitudeEulerAnglesMatchQuaternion) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(47.0, 8.0, 400.0));
  VehicleState state;
  // Rz(-120 deg) * Ry(20 deg) * Rx(-35 deg), built here from AngleAxis, not core's helpers.
  state.q_world_body = Eigen::AngleAxisd(-120.0 * kDeg, Eigen::Vector3d::UnitZ()) *
                       Eigen::AngleAxisd(20.0 * kDeg, Eigen::Vector3d::UnitY()) *
                       Eigen::AngleAxisd(-35.0 * kDeg, Eigen::Vector3d::UnitX());
  const NavMessages nav = toNavMessages(state, frame, 0.0);
  EXPECT_NEAR(nav.attitude.roll_rad, -35.0 * kDeg, 1e-12);
  EXPECT_NEAR(nav.attitude.pitch_rad, 20.0 * kDeg, 1e-12);
  EXPECT_NEAR(nav.attitude.yaw_rad, -120.0 * kDeg, 1e-12);
}

// NAV position of a known NED offset equals GeographicLib's LocalCartesian reverse of it.
TEST(SimMessages, NavPositionMatchesGeographicLib) {
  const double lat0_deg = 37.3, lon0_deg = -113.0, h0_m = 1500.0;
  const core::LocalNedFrame frame(core::geodeticFromDegrees(lat0_deg, lon0_deg, h0_m));
  VehicleState state;
  state.p_ned_m = Eigen::Vector3d(1200.0, -800.0, -150.0);
  const NavMessages nav = toNavMessages(state, frame, 1480.0);

  const GeographicLib::LocalCartesian enu(lat0_deg, lon0_deg, h0_m);
  double lat_deg = 0, lon_deg = 0, h_m = 0;
  enu.Reverse(-800.0, 1200.0, 150.0, lat_deg, lon_deg, h_m);
  EXPECT_NEAR(nav.position.latitude_rad, lat_deg * kDeg, 1e-12);
  EXPECT_NEAR(nav.position.longitude_rad, lon_deg * kDeg, 1e-12);
  EXPECT_NEAR(nav.position.altitude_m, h_m, 1e-6);
  EXPECT_NEAR(nav.position.altitude_rel_m, h_m - 1480.0, 1e-6);
  // 150 m up on the tangent plane, which rises above the ellipsoid by d^2 / 2R = 0.163 m at
  // d = 1442 m: about 150.163 m above the origin's height.
  EXPECT_NEAR(nav.position.altitude_m - h0_m, 150.163, 0.005);
}

// ---------------------------------------------------------------- flight logs

// pose_t on POSE_TRUTH reads back as the same poses at the messages' utime; bad ones skipped.
TEST(SimMessagesFlightLog, PoseTruthReadsBackExactly) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(37.3, -113.0, 1500.0));
  const std::string path = tempPath("pose_truth.lcmlog");
  std::vector<VehicleState> states;
  {
    core::LcmLogWriter log(path);
    for (int i = 0; i < 6; ++i) {
      states.push_back(makeState(1'000'000 + 100'000 * i, i));
      writeMessage(log, 42 + i, "POSE_TRUTH", toPoseMessage(states.back()));
      writeMessage(log, 42 + i, "NAV_POSITION", toNavMessages(states.back(), frame, 0).position);
      writeMessage(log, 42 + i, "NAV_ATTITUDE", toNavMessages(states.back(), frame, 0).attitude);
    }
    nadir::pose_t not_finite = toPoseMessage(makeState(1'050'000, 9.0));
    not_finite.pos[0] = std::numeric_limits<double>::infinity();
    writeMessage(log, 0, "POSE_TRUTH", not_finite);
  }
  FlightLogStats stats;
  const Trajectory trajectory = readFlightLog(path, {}, frame, &stats);
  EXPECT_TRUE(stats.from_pose_channel);
  EXPECT_EQ(stats.poses, 6);
  EXPECT_EQ(stats.decode_failures, 0);
  EXPECT_EQ(stats.invalid_messages, 1);
  EXPECT_TRUE(stats.damage.empty()) << stats.damage;
  ASSERT_EQ(trajectory.poses().size(), states.size());
  for (std::size_t i = 0; i < states.size(); ++i) {
    const TrajectoryPose& pose = trajectory.poses()[i];
    EXPECT_EQ(pose.utime, states[i].utime);
    EXPECT_EQ(pose.p_ned_m, states[i].p_ned_m);
    EXPECT_NEAR((pose.q_world_body.coeffs() - states[i].q_world_body.coeffs()).norm(), 0.0, 1e-15);
  }
}

// Out-of-order poses are sorted, exact repeats dropped; two different poses at one time throw.
TEST(SimMessagesFlightLog, SortsDropsDuplicatesAndRefusesConflicts) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(37.3, -113.0, 1500.0));
  const std::string path = tempPath("unordered.lcmlog");
  {
    core::LcmLogWriter log(path);
    for (int i : {2, 0, 1, 1, 3}) {
      writeMessage(log, 0, "POSE_TRUTH", toPoseMessage(makeState(1'000'000 * i, i)));
    }
  }
  FlightLogStats stats;
  const Trajectory trajectory = readFlightLog(path, {}, frame, &stats);
  EXPECT_EQ(stats.duplicates, 1);
  ASSERT_EQ(trajectory.poses().size(), 4u);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(trajectory.poses()[i].utime, 1'000'000 * i);

  const std::string conflict = tempPath("conflict.lcmlog");
  {
    core::LcmLogWriter log(conflict);
    writeMessage(log, 0, "POSE_TRUTH", toPoseMessage(makeState(0, 0)));
    writeMessage(log, 0, "POSE_TRUTH", toPoseMessage(makeState(1'000'000, 1)));
    writeMessage(log, 0, "POSE_TRUTH", toPoseMessage(makeState(1'000'000, 2)));
  }
  try {
    readFlightLog(conflict, {}, frame);
    FAIL() << "two different poses at one time were accepted";
  } catch (const TrajectoryError& e) {
    EXPECT_NE(std::string(e.what()).find(conflict), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not increasing"), std::string::npos) << e.what();
  }
}

// 4 Hz positions + 10 Hz attitudes give poses at the position times with SLERPed attitudes.
TEST(SimMessagesFlightLog, NavPositionAndAttitudeArePairedBySlerp) {
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
  const Trajectory trajectory = readFlightLog(path, channels, frame, &stats);
  EXPECT_FALSE(stats.from_pose_channel);
  EXPECT_EQ(stats.decode_failures, 1);
  EXPECT_EQ(stats.positions_outside_attitude_span, 2);

  const std::vector<std::int64_t> offsets = {150'000, 400'000, 650'000, 900'000};
  ASSERT_EQ(trajectory.poses().size(), offsets.size());
  for (std::size_t i = 0; i < offsets.size(); ++i) {
    const TrajectoryPose& pose = trajectory.poses()[i];
    EXPECT_EQ(pose.utime, t0 + offsets[i]);
    EXPECT_NEAR((pose.p_ned_m - positionAt(offsets[i])).norm(), 0.0, 1e-6);
  }
  // 0.65 s lies halfway between the attitudes at 0.6 s and 0.7 s.
  const Eigen::Quaterniond expected = handSlerp(attitudeAt(6), attitudeAt(7), 0.5);
  EXPECT_NEAR(angleBetween(trajectory.poses()[2].q_world_body, expected), 0.0, 1e-12);
  // 0.4 s is exactly an attitude sample; 0.15 s is halfway between 0.1 s and 0.2 s.
  EXPECT_NEAR(angleBetween(trajectory.poses()[1].q_world_body, attitudeAt(4)), 0.0, 1e-12);
  EXPECT_NEAR(angleBetween(trajectory.poses()[0].q_world_body,
                           handSlerp(attitudeAt(1), attitudeAt(2), 0.5)),
              0.0, 1e-12);
}

// A log with neither pose_t nor position/attitude pairs throws, naming file and channels.
TEST(SimMessagesFlightLog, LogWithNeitherIsRefused) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(37.3, -113.0, 1500.0));
  const std::string path = tempPath("imu_only.lcmlog");
  {
    core::LcmLogWriter log(path);
    nadir::imu_t imu{};
    for (int i = 0; i < 3; ++i) writeMessage(log, i, "IMU", imu);
    // Positions without any attitude make no pairs either.
    writeMessage(log, 5, "NAV_POSITION", toNavMessages(makeState(5, 0), frame, 0.0).position);
  }
  try {
    readFlightLog(path, {}, frame);
    FAIL() << "a log without truth was accepted";
  } catch (const TrajectoryError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  path + " has no pose_t on POSE_TRUTH and no NAV_POSITION/NAV_ATTITUDE pairs"),
              std::string::npos)
        << e.what();
  }
}

// A file that is not an LCM log, and a missing file, are errors naming the file.
TEST(SimMessagesFlightLog, NonLogFileIsRefused) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(37.3, -113.0, 1500.0));
  const std::string path = tempPath("not_a_log.csv");
  std::ofstream(path) << "time_s,lat_deg,lon_deg\n0,37.3,-113.0\n";
  try {
    readFlightLog(path, {}, frame);
    FAIL() << "a CSV file was read as an LCM log";
  } catch (const TrajectoryError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not an LCM log"), std::string::npos) << e.what();
  }
  const std::string missing = tempPath("does_not_exist.lcmlog");
  try {
    readFlightLog(missing, {}, frame);
    FAIL() << "a missing file was accepted";
  } catch (const TrajectoryError& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
}

// A log cut inside its last event gives the poses before the cut and reports the truncation.
TEST(SimMessagesFlightLog, TruncatedLogKeepsWhatWasRead) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(37.3, -113.0, 1500.0));
  const std::string path = tempPath("truncated.lcmlog");
  {
    core::LcmLogWriter log(path);
    for (int i = 0; i < 5; ++i) {
      writeMessage(log, i, "POSE_TRUTH", toPoseMessage(makeState(1'000'000 * i, i)));
    }
  }
  const auto size = std::filesystem::file_size(path);
  std::filesystem::resize_file(path, size - 40);
  FlightLogStats stats;
  const Trajectory trajectory = readFlightLog(path, {}, frame, &stats);
  ASSERT_EQ(trajectory.poses().size(), 4u);
  EXPECT_EQ(trajectory.endUtime(), 3'000'000);
  EXPECT_NE(stats.damage.find("truncated"), std::string::npos) << stats.damage;
}

}  // namespace
}  // namespace nadir::sim
