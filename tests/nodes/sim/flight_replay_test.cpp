// Recorded flights replayed as truth: TUM and flight CSV through the replay, its
// interpolation and rates, and bad files refused with their place.

#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>

#include <gtest/gtest.h>

#include "core/clock.h"
#include "core/frames.h"
#include "core/geodesy.h"
#include "core/trajectory.h"
#include "nodes/sim/flight_replay.h"
#include "nodes/sim/vehicles.h"

namespace nadir::sim {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

std::string writeFile(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "nadir_trajectory_" + name;
  std::ofstream(path) << text;
  return path;
}

double angleBetween(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return Eigen::AngleAxisd(a.conjugate() * b).angle();
}

// Halfway between two TUM poses: the mean position and half the rotation (yaw 0 -> 90 gives 45).
TEST(FlightReplay, TumInterpolatesLinearlyAndBySlerp) {
  const double s = std::sqrt(0.5);
  const std::string path = writeFile("two.tum",
                                     "# t x y z qx qy qz qw\n"
                                     "10.0 0 0 -100 0 0 0 1\n"
                                     "12.0 40 20 -110 0 0 " +
                                         std::to_string(s) + " " + std::to_string(s) + "\n");
  const FlightReplay trajectory(core::readTum(path), path);
  const VehicleState mid = trajectory.at(11'000'000);
  EXPECT_NEAR((mid.p_ned_m - Eigen::Vector3d(20, 10, -105)).norm(), 0.0, 1e-9);
  EXPECT_NEAR(core::rpyFromQuaternion(mid.q_world_body).yaw_rad, 45.0 * kDeg, 1e-6);
  // 40 m north and 20 m east and 10 m up in 2 s.
  EXPECT_NEAR((mid.v_ned_mps - Eigen::Vector3d(20, 10, -5)).norm(), 0.0, 1e-9);
  // 90 deg of yaw in 2 s about body z.
  EXPECT_NEAR((mid.omega_body_rps - Eigen::Vector3d(0, 0, 45.0 * kDeg)).norm(), 0.0, 1e-6);
  // Outside the recording: the ends.
  EXPECT_NEAR(trajectory.at(0).p_ned_m.z(), -100.0, 1e-12);
}

// A fixed-wing flight written as a flight CSV (lat, lon, alt, roll, pitch, yaw) at 10 Hz
// comes back through the truth stream at its samples exactly (to the file's precision)
// and between them within the chord error of a 41 m turn (2 m arcs: 1.2 cm).
TEST(FlightReplay, FlightCsvRoundTripsWithinInterpolationError) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(37.3, -113.0, 1500.0));
  FixedWingParams params;
  params.airspeed_mps = 20.0;
  FixedWing aircraft(params, {0, 0, -100}, 0.0,
                     {Eigen::Vector3d(300, 0, -120), Eigen::Vector3d(300, 300, -120),
                      Eigen::Vector3d(0, 300, -100)});
  std::vector<VehicleState> truth;  // every step, 400 Hz
  std::string csv = "time_s,lat_deg,lon_deg,alt_m,roll_deg,pitch_deg,yaw_deg,note\n";
  for (int i = 0; i < 400 * 40; ++i) {
    aircraft.step();
    const VehicleState& state = aircraft.state();
    truth.push_back(state);
    if (i % 40 == 39) {
      const core::Geodetic g = frame.geodeticFromNed(state.p_ned_m);
      const core::RollPitchYaw rpy = core::rpyFromQuaternion(state.q_world_body);
      char row[256];
      std::snprintf(row, sizeof(row), "%.6f,%.12f,%.12f,%.6f,%.9f,%.9f,%.9f,x\n",
                    core::secondsFromUtime(state.utime), g.lat_rad / kDeg, g.lon_rad / kDeg,
                    g.alt_m, rpy.roll_rad / kDeg, rpy.pitch_rad / kDeg, rpy.yaw_rad / kDeg);
      csv += row;
    }
  }
  const std::string csv_path = writeFile("flight.csv", csv);
  const FlightReplay trajectory(core::readFlightCsv(csv_path, frame), csv_path);
  double worst_at_samples_m = 0.0, worst_between_m = 0.0, worst_angle_rad = 0.0;
  for (std::size_t i = 39; i + 40 < truth.size(); ++i) {
    const VehicleState replayed = trajectory.at(truth[i].utime);
    const double error_m = (replayed.p_ned_m - truth[i].p_ned_m).norm();
    if (i % 40 == 39) {
      worst_at_samples_m = std::max(worst_at_samples_m, error_m);
    } else {
      worst_between_m = std::max(worst_between_m, error_m);
    }
    worst_angle_rad =
        std::max(worst_angle_rad, angleBetween(replayed.q_world_body, truth[i].q_world_body));
  }
  EXPECT_LT(worst_at_samples_m, 1e-3);
  EXPECT_LT(worst_between_m, 0.02);
  // Within an interval the bank moves at most 45 deg/s * 0.1 s = 4.5 deg, and where the
  // roll rate starts or stops inside it, SLERP cuts the corner by at most half of that.
  EXPECT_LT(worst_angle_rad, 2.25 * kDeg);
}

// Bad files are refused naming the file, the line or the missing column.
TEST(FlightReplay, BadInputIsRefusedWithItsPlace) {
  const core::LocalNedFrame frame(core::geodeticFromDegrees(37.3, -113.0, 1500.0));
  const auto message = [](auto&& f) {
    try {
      f();
    } catch (const core::TrajectoryError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  const std::string one = writeFile("one.tum", "1.0 0 0 0 0 0 0 1\n");
  EXPECT_NE(message([&] { FlightReplay(core::readTum(one), one); }).find("at least two poses"),
            std::string::npos);
  const std::string back = writeFile("back.tum", "2.0 0 0 0 0 0 0 1\n1.0 0 0 0 0 0 0 1\n");
  EXPECT_NE(message([&] { FlightReplay(core::readTum(back), back); }).find("back.tum:2"),
            std::string::npos);
  const std::string short_line = writeFile("short.tum", "1.0 0 0 0 0 0 0 1\n2.0 0 0\n");
  EXPECT_NE(
      message([&] { FlightReplay(core::readTum(short_line), short_line); }).find("short.tum:2"),
      std::string::npos);
  const std::string no_yaw =
      writeFile("noyaw.csv", "time_s,lat_deg,lon_deg,alt_m,roll_deg,pitch_deg\n");
  EXPECT_NE(message([&] { core::readFlightCsv(no_yaw, frame); }).find("'yaw_deg'"),
            std::string::npos);
  const std::string bad_number = writeFile("bad.csv",
                                           "time_s,lat_deg,lon_deg,alt_m,roll_deg,pitch_deg,yaw_"
                                           "deg\n0,37.3,-113,1500,0,0,0\n1,37.3,-113,abc,0,0,0\n");
  EXPECT_NE(message([&] { core::readFlightCsv(bad_number, frame); }).find("bad.csv:3: 'abc'"),
            std::string::npos);
  // Found by fuzzing (fuzz/regressions/trajectory): a latitude past a pole
  // threw std::invalid_argument, without the file; a column named twice was
  // read from its last place.
  const std::string pole = writeFile("pole.csv",
                                     "time_s,lat_deg,lon_deg,alt_m,roll_deg,pitch_deg,yaw_deg\n"
                                     "0,113.0,-113,1500,0,0,0\n");
  EXPECT_NE(message([&] {
              core::readFlightCsv(pole, frame);
            }).find("pole.csv:2: lat_deg 113.0 is outside [-90, 90]"),
            std::string::npos);
  const std::string twice =
      writeFile("twice.csv", "time_s,lat_deg,lon_deg,alt_m,roll_deg,lon_deg,pitch_deg,yaw_deg\n");
  EXPECT_NE(message([&] {
              core::readFlightCsv(twice, frame);
            }).find("twice.csv: the header names column 'lon_deg' twice"),
            std::string::npos);
  EXPECT_NE(message([&] { core::readTum("/nonexistent/x.tum"); }).find("/nonexistent/x.tum"),
            std::string::npos);
}

}  // namespace
}  // namespace nadir::sim
