// The simulator's truth as flight stacks publish it (the NAV_* split), and the
// standard atmosphere of the barometer's pressure.

#include "nodes/sim/nav_truth.h"

#include <gtest/gtest.h>
#include <GeographicLib/LocalCartesian.hpp>

#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

#include "core/frames.h"
#include "nodes/sim/sensors.h"

namespace nadir::sim {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// ---------------------------------------------------------------- pressure

// ISA pressure matches the standard-atmosphere table at 0, 1, 5, 11 and 20 km within 1 Pa.
TEST(NavTruth, StandardAtmosphereMatchesIsaTable) {
  EXPECT_NEAR(standardAtmospherePressure_pa(0.0), 101325.0, 1.0);
  EXPECT_NEAR(standardAtmospherePressure_pa(1000.0), 89874.6, 1.0);
  EXPECT_NEAR(standardAtmospherePressure_pa(5000.0), 54019.9, 1.0);
  EXPECT_NEAR(standardAtmospherePressure_pa(11000.0), 22632.1, 1.0);
  EXPECT_NEAR(standardAtmospherePressure_pa(20000.0), 5474.89, 1.0);
  // Continuous across the tropopause: both layers agree just above and below 11 km.
  EXPECT_NEAR(standardAtmospherePressure_pa(11000.001), standardAtmospherePressure_pa(11000.0),
              0.1);
}

// ---------------------------------------------------------------- NAV_* split

// Level heading east: yaw 90 deg, q = (cos45, 0, 0, sin45); rates in deg/s; velocity in NED.
TEST(NavTruth, NavAttitudeRatesAndVelocity) {
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
  EXPECT_NEAR(nav.attitude.q_world_body.w(), c45, 1e-15);
  EXPECT_NEAR(nav.attitude.q_world_body.x(), 0.0, 1e-15);
  EXPECT_NEAR(nav.attitude.q_world_body.y(), 0.0, 1e-15);
  EXPECT_NEAR(nav.attitude.q_world_body.z(), c45, 1e-15);

  EXPECT_EQ(nav.rates.utime, 2'000'000);
  EXPECT_NEAR(nav.rates.omega_body_dps[0], 45.0, 1e-12);
  EXPECT_NEAR(nav.rates.omega_body_dps[1], -1.0, 1e-12);
  EXPECT_NEAR(nav.rates.omega_body_dps[2], 28.64788975654116, 1e-12);  // 0.5 rad/s

  EXPECT_EQ(nav.velocity.utime, 2'000'000);
  EXPECT_EQ(nav.velocity.v_ned_mps[0], 0.5);
  EXPECT_EQ(nav.velocity.v_ned_mps[1], 20.0);
  EXPECT_EQ(nav.velocity.v_ned_mps[2], -1.0);
  EXPECT_EQ(nav.position.utime, 2'000'000);
}

// Roll, pitch and yaw in attitude_t are the Z-Y-X angles the quaternion was built from.
TEST(NavTruth, NavAttitudeEulerAnglesMatchQuaternion) {
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
TEST(NavTruth, NavPositionMatchesGeographicLib) {
  const double lat0_deg = 37.3, lon0_deg = -113.0, h0_m = 1500.0;
  const core::LocalNedFrame frame(core::geodeticFromDegrees(lat0_deg, lon0_deg, h0_m));
  VehicleState state;
  state.p_ned_m = Eigen::Vector3d(1200.0, -800.0, -150.0);
  const NavMessages nav = toNavMessages(state, frame, 1480.0);

  const GeographicLib::LocalCartesian enu(lat0_deg, lon0_deg, h0_m);
  double lat_deg = 0, lon_deg = 0, h_m = 0;
  enu.Reverse(-800.0, 1200.0, 150.0, lat_deg, lon_deg, h_m);
  EXPECT_NEAR(nav.position.lat_rad, lat_deg * kDeg, 1e-12);
  EXPECT_NEAR(nav.position.lon_rad, lon_deg * kDeg, 1e-12);
  EXPECT_NEAR(nav.position.alt_m, h_m, 1e-6);
  EXPECT_NEAR(nav.position.alt_rel_m, h_m - 1480.0, 1e-6);
  // 150 m up on the tangent plane, which rises above the ellipsoid by d^2 / 2R = 0.163 m at
  // d = 1442 m: about 150.163 m above the origin's height.
  EXPECT_NEAR(nav.position.alt_m - h0_m, 150.163, 0.005);
}

}  // namespace
}  // namespace nadir::sim
