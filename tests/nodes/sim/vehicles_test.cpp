// Vehicle models against their limits and against turn geometry worked out by hand.

#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "core/frames.h"
#include "nodes/sim/vehicles.h"

namespace nadir::sim {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// Radius of the circle through three points.
double circumradius(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const double ab = (a - b).norm(), bc = (b - c).norm(), ca = (c - a).norm();
  const double cross = std::abs((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
  return ab * bc * ca / (2.0 * cross);
}

// Over a zig-zag, the bank never exceeds its limit nor changes faster than the roll-rate limit.
TEST(FixedWing, NeverExceedsBankAndRollRateLimits) {
  FixedWingParams params;
  params.airspeed_mps = 25.0;
  params.max_bank_deg = 30.0;
  params.max_roll_rate_dps = 25.0;
  std::vector<Eigen::Vector3d> zigzag;
  for (int i = 1; i <= 8; ++i) zigzag.emplace_back(400.0 * i, (i % 2 ? 300.0 : -300.0), -100.0);
  FixedWing aircraft(params, {0, 0, -100}, 0.0, zigzag);
  double previous = aircraft.bank_rad(), largest = 0.0;
  const double max_step = 25.0 * kDeg * params.step_s;
  for (int i = 0; i < 400 * 200 && !aircraft.finished(); ++i) {
    aircraft.step();
    ASSERT_LE(std::abs(aircraft.bank_rad()), 30.0 * kDeg + 1e-12);
    ASSERT_LE(std::abs(aircraft.bank_rad() - previous), max_step + 1e-12);
    largest = std::max(largest, std::abs(aircraft.bank_rad()));
    previous = aircraft.bank_rad();
  }
  EXPECT_TRUE(aircraft.finished());
  EXPECT_NEAR(largest, 30.0 * kDeg, 1e-9) << "the zig-zag should need full bank";
}

// A steady turn at full bank has radius v^2 / (g tan(bank)): 20 m/s at 45 deg -> 40.79 m.
TEST(FixedWing, SteadyTurnRadiusMatchesCoordinatedTurn) {
  FixedWingParams params;
  params.airspeed_mps = 20.0;
  params.max_bank_deg = 45.0;
  params.max_roll_rate_dps = 90.0;
  // A waypoint behind: the aircraft turns round at full bank.
  FixedWing aircraft(params, {0, 0, -100}, 0.0, {Eigen::Vector3d(-2000.0, 1.0, -100.0)});
  while (std::abs(aircraft.bank_rad()) < 45.0 * kDeg - 1e-12) aircraft.step();
  std::vector<Eigen::Vector2d> points;
  const double start_heading = aircraft.heading_rad();
  for (int i = 0; i < 3; ++i) {
    while (std::abs(std::remainder(aircraft.heading_rad() - start_heading, 2 * std::numbers::pi)) <
           i * 30.0 * kDeg) {
      aircraft.step();
      ASSERT_NEAR(std::abs(aircraft.bank_rad()), 45.0 * kDeg, 1e-12) << "left full bank too early";
    }
    points.emplace_back(aircraft.state().p_ned_m.x(), aircraft.state().p_ned_m.y());
  }
  const double expected_m = 20.0 * 20.0 / (9.80665 * std::tan(45.0 * kDeg));
  EXPECT_NEAR(circumradius(points[0], points[1], points[2]), expected_m, 0.01 * expected_m);
}

// Wind turns air velocity into a different ground velocity: level, straight, with a 5 m/s
// crosswind.
TEST(FixedWing, WindAddsToGroundVelocity) {
  FixedWingParams params;
  params.wind_ned_mps = {0.0, 5.0, 0.0};
  FixedWing aircraft(params, {0, 0, -100}, 0.0, {Eigen::Vector3d(5000.0, 0.0, -100.0)});
  for (int i = 0; i < 24000; ++i) aircraft.step();  // 60 s: settled on the leg
  EXPECT_NEAR(aircraft.state().p_ned_m.y(), 0.0, 0.5);
  // Holding the leg, the aircraft crabs: ground track north, airspeed 20 m/s into the wind.
  EXPECT_NEAR(aircraft.state().v_ned_mps.y(), 0.0, 0.05);
  EXPECT_NEAR(aircraft.state().v_ned_mps.x(), std::sqrt(20.0 * 20.0 - 25.0), 0.05);
}

// Two runs with one seed are identical, also with turbulence; another seed differs.
TEST(FixedWing, SameSeedSameFlight) {
  FixedWingParams params;
  params.turbulence_mps = 1.5;
  params.seed = 7;
  const std::vector<Eigen::Vector3d> waypoints = {{600, 200, -120}, {0, 600, -80}};
  FixedWing a(params, {0, 0, -100}, 0.0, waypoints), b(params, {0, 0, -100}, 0.0, waypoints);
  params.seed = 8;
  FixedWing c(params, {0, 0, -100}, 0.0, waypoints);
  for (int i = 0; i < 8000; ++i) {
    a.step();
    b.step();
    c.step();
  }
  EXPECT_EQ(a.state().p_ned_m, b.state().p_ned_m);
  EXPECT_EQ(a.state().q_world_body.coeffs(), b.state().q_world_body.coeffs());
  EXPECT_NE(a.state().p_ned_m, c.state().p_ned_m);
}

// A leg shorter than the turns at its ends need is refused, naming the waypoint; a short
// straight leg is flyable; bad speeds are refused.
TEST(FixedWing, UnreachableWaypointsAndBadParamsAreRefused) {
  FixedWingParams params;  // 20 m/s, 45 deg: turn radius 40.8 m, 90 deg turns lead by 40.8 m
  try {
    // 60 m between two 90 deg turns, which need 81.6 m.
    FixedWing(params, {0, 0, -100}, 0.0,
              {Eigen::Vector3d(500, 0, -100), Eigen::Vector3d(500, 60, -100),
               Eigen::Vector3d(0, 60, -100)});
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("waypoint 2 is 60"), std::string::npos)
        << error.what();
    EXPECT_NE(std::string(error.what()).find("need 81.6"), std::string::npos) << error.what();
  }
  // 90 m between the same turns is enough, and so is 30 m on a straight line.
  EXPECT_NO_THROW(FixedWing(params, {0, 0, -100}, 0.0,
                            {Eigen::Vector3d(500, 0, -100), Eigen::Vector3d(500, 90, -100),
                             Eigen::Vector3d(0, 90, -100)}));
  EXPECT_NO_THROW(FixedWing(params, {0, 0, -100}, 0.0,
                            {Eigen::Vector3d(500, 0, -100), Eigen::Vector3d(530, 0, -100)}));
  params.airspeed_mps = -3.0;
  EXPECT_THROW(FixedWing(params, {0, 0, 0}, 0.0, {Eigen::Vector3d(500, 0, 0)}), core::ParamError);
}

// A leg with its own speed: the airspeed changes towards it at max_acceleration_mps2 and
// no faster, and the next leg's 0 returns to the cruise airspeed.
TEST(FixedWing, LegSpeedsChangeAirspeedAtTheAccelerationLimit) {
  FixedWingParams params;
  params.airspeed_mps = 25.0;
  params.max_acceleration_mps2 = 0.5;
  FixedWing aircraft(params, {0, 0, -100}, 0.0,
                     std::vector<Waypoint>{{Eigen::Vector3d(600, 0, -100), 15.0},
                                           {Eigen::Vector3d(1600, 0, -100), 0.0}});
  EXPECT_DOUBLE_EQ(aircraft.airspeed_mps(), 15.0);  // starts at its first leg's speed
  double max_change = 0.0, previous = aircraft.airspeed_mps();
  bool reached_cruise = false;
  while (!aircraft.finished()) {
    aircraft.step();
    max_change = std::max(max_change, std::abs(aircraft.airspeed_mps() - previous));
    previous = aircraft.airspeed_mps();
    if (aircraft.nextWaypoint() == 0) {
      EXPECT_DOUBLE_EQ(aircraft.airspeed_mps(), 15.0);
    }
    reached_cruise = reached_cruise || aircraft.airspeed_mps() == 25.0;
  }
  EXPECT_TRUE(reached_cruise);
  EXPECT_LE(max_change, 0.5 * params.step_s + 1e-12);
  // Level flight along north: the ground speed is the airspeed.
  EXPECT_NEAR(aircraft.state().v_ned_mps.norm(), 25.0, 1e-9);
}

// McConville et al.'s (2020) rectangle: 50 m x 25 m flown four times is 600 m, and the multirotor
// faces along each leg, yawing 90 deg at every corner.
TEST(Multirotor, RectangleWithNinetyDegreeYaws) {
  MultirotorParams params;
  const std::vector<Eigen::Vector3d> corners = {{50, 0, -5}, {50, 25, -5}, {0, 25, -5}, {0, 0, -5}};
  std::vector<Eigen::Vector3d> laps;
  for (int lap = 0; lap < 4; ++lap) laps.insert(laps.end(), corners.begin(), corners.end());
  Multirotor drone(params, {0, 0, -5}, 0.0, laps);
  double length_m = 0.0;
  Eigen::Vector3d previous = drone.state().p_ned_m;
  std::vector<double> yaw_while_moving;
  while (!drone.finished()) {
    drone.step();
    length_m += (drone.state().p_ned_m - previous).norm();
    if (drone.state().v_ned_mps.norm() > 1.0) {
      const Eigen::Vector3d v = drone.state().v_ned_mps;
      EXPECT_NEAR(std::remainder(drone.yaw_rad() - std::atan2(v.y(), v.x()), 2 * std::numbers::pi),
                  0.0, 1e-9);
    }
    previous = drone.state().p_ned_m;
    ASSERT_LT(drone.state().utime, 1'000'000'000) << "never finished";
  }
  EXPECT_NEAR(length_m, 600.0, 0.02 * 600.0);
  // Back at the start after the last leg west: yaw -90 deg.
  EXPECT_NEAR(std::remainder(drone.yaw_rad() + std::numbers::pi / 2, 2 * std::numbers::pi), 0.0,
              1e-9);
}

// Guided on a noisy estimate (its height 3 cm off one way or the other at
// random each step, as a rangefinder's), the multirotor never stands exactly
// on a waypoint; it takes each as reached within its acceptance radii (0.3 m
// across, 0.5 m in height), brakes to a stop there and flies the next leg.
// The truth ends within the radii of the last waypoint, at rest.
TEST(Multirotor, ReachesWaypointsOnANoisyEstimateWithinItsAcceptanceRadii) {
  MultirotorParams params;
  const std::vector<Eigen::Vector3d> corners = {{20, 0, -5}, {20, 10, -5}, {0, 10, -5}};
  Multirotor drone(params, {0, 0, -5}, 0.0, corners);
  std::mt19937_64 rng(7);
  std::size_t next_seen = 0;
  while (!drone.finished()) {
    drone.setPositionError(Eigen::Vector3d(0.0, 0.0, rng() % 2 == 0 ? 0.03 : -0.03));
    drone.step();
    if (drone.nextWaypoint() > next_seen) {
      // Reached: at rest, and within the radii of the waypoint it left.
      const Eigen::Vector3d off = drone.state().p_ned_m - corners[next_seen];
      EXPECT_LE(off.head<2>().norm(), 0.3 + 1e-9) << "waypoint " << next_seen;
      EXPECT_LE(std::abs(off.z()), 0.5 + 0.03) << "waypoint " << next_seen;
      EXPECT_EQ(drone.state().v_ned_mps.norm(), 0.0) << "waypoint " << next_seen;
      next_seen = drone.nextWaypoint();
    }
    ASSERT_LT(drone.state().utime, 200'000'000) << "hovered at waypoint " << next_seen;
  }
  EXPECT_EQ(next_seen, corners.size());
}

// The multirotor tilts into its acceleration: nose down to speed up forward.
TEST(Multirotor, TiltsWithAcceleration) {
  MultirotorParams params;
  params.acceleration_mps2 = 2.0;
  Multirotor drone(params, {0, 0, -10}, 0.0, {Eigen::Vector3d(100, 0, -10)});
  // 11.5 deg at 60 deg/s takes 0.19 s; after 0.5 s the vehicle is still accelerating.
  for (int i = 0; i < 200; ++i) drone.step();
  const core::RollPitchYaw rpy = core::rpyFromQuaternion(drone.state().q_world_body);
  // 2 m/s^2 forward: pitch = -atan(2 / g) = -11.53 deg.
  EXPECT_NEAR(rpy.pitch_rad, -std::atan(2.0 / 9.80665), 1e-9);
  EXPECT_NEAR(rpy.roll_rad, 0.0, 1e-9);
}

// Through stops and starts at every corner the tilt never exceeds atan(a_max / g): the
// stop on a waypoint does not spike the acceleration.
TEST(Multirotor, TiltStaysWithinTheAccelerationLimit) {
  MultirotorParams params;  // 3 m/s, 1.5 m/s^2: at most atan(1.5 / g) = 8.70 deg
  Multirotor drone(params, {0, 0, -5}, 0.0,
                   {Eigen::Vector3d(50, 0, -5), Eigen::Vector3d(50, 25, -5),
                    Eigen::Vector3d(0, 25, -5), Eigen::Vector3d(0, 0, -5)});
  double max_tilt = 0.0;
  while (!drone.finished()) {
    drone.step();
    const Eigen::Vector3d body_down = drone.state().q_world_body * Eigen::Vector3d::UnitZ();
    max_tilt = std::max(max_tilt, std::acos(std::clamp(body_down.z(), -1.0, 1.0)));
  }
  EXPECT_LE(max_tilt, std::atan(1.5 / 9.80665) + 1e-9);
  EXPECT_GT(max_tilt, std::atan(1.5 / 9.80665) - 1e-3);  // braking does reach the limit
}

// The tilt changes no faster than the attitude controller's rate, even when braking starts.
TEST(Multirotor, TiltRateIsLimited) {
  MultirotorParams params;
  params.max_tilt_rate_dps = 60.0;
  Multirotor drone(params, {0, 0, -5}, 0.0,
                   {Eigen::Vector3d(20, 0, -5), Eigen::Vector3d(20, 20, -5)});
  Eigen::Vector3d previous_down = drone.state().q_world_body * Eigen::Vector3d::UnitZ();
  double max_rate = 0.0;
  while (!drone.finished()) {
    drone.step();
    const Eigen::Vector3d down = drone.state().q_world_body * Eigen::Vector3d::UnitZ();
    max_rate = std::max(max_rate,
                        std::acos(std::clamp(down.dot(previous_down), -1.0, 1.0)) / params.step_s);
    previous_down = down;
  }
  // Roll and pitch each at most 60 deg/s: the body axis swings at most sqrt(2) x that.
  EXPECT_LE(max_rate, std::sqrt(2.0) * 60.0 * kDeg * 1.001);
  EXPECT_GT(max_rate, 30.0 * kDeg);
}

// The rover's turn at full steering has radius wheelbase / tan(steer): 0.3 m at
// 30 deg -> 0.520 m; it never steers past its limits; it reaches a slalom's gates.
TEST(Rover, BicycleTurnRadiusAndSteeringLimits) {
  RoverParams params;
  Rover rover(params, {0, 0, 0}, 0.0, {Eigen::Vector3d(-20.0, 0.1, 0.0)});
  const double max_step = params.max_steer_rate_dps * kDeg * params.step_s;
  double previous = rover.steer_rad();
  while (std::abs(rover.steer_rad()) < 30.0 * kDeg - 1e-12) {
    rover.step();
    ASSERT_LE(std::abs(rover.steer_rad() - previous), max_step + 1e-12);
    previous = rover.steer_rad();
  }
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 100; ++j) {
      rover.step();
      ASSERT_NEAR(std::abs(rover.steer_rad()), 30.0 * kDeg, 1e-12);
    }
    points.emplace_back(rover.state().p_ned_m.x(), rover.state().p_ned_m.y());
  }
  const double expected_m = 0.3 / std::tan(30.0 * kDeg);
  EXPECT_NEAR(circumradius(points[0], points[1], points[2]), expected_m, 0.01 * expected_m);
}

// Through a slalom of gates 3 m apart, the rover passes within its arrival radius of each.
TEST(Rover, DrivesASlalom) {
  RoverParams params;
  std::vector<Eigen::Vector3d> gates;
  for (int i = 1; i <= 6; ++i) gates.emplace_back(3.0 * i, (i % 2 ? 0.6 : -0.6), 0.0);
  Rover rover(params, {0, 0, 0}, 0.0, gates);
  for (int i = 0; i < 400 * 60 && !rover.finished(); ++i) {
    rover.step();
    ASSERT_LE(std::abs(rover.steer_rad()), 30.0 * kDeg + 1e-12);
  }
  EXPECT_TRUE(rover.finished());
  EXPECT_NEAR(rover.state().p_ned_m.x(), 18.0, params.arrival_radius_m);
}

}  // namespace
}  // namespace nadir::sim
