// The guidance flown on a navigation source: from the GPS denial on, the
// vehicle steers by the source's position (its error against the truth at its
// time held between fixes), so the truth ends off the route by that error;
// each waypoint taken as reached is reported with where the vehicle believed it
// was and where it truly was.

#include <gtest/gtest.h>

#include <memory>

#include "core/geodesy.h"
#include "nodes/sim/simulator.h"
#include "terrain/arena_world.h"

namespace nadir::sim {
namespace {

// A multirotor flying 20 m north then 20 m east at 2 m above a flat floor, at
// 4 m/s, stopping on each waypoint.
SimParams squareLeg(const std::string& source, double denied_after_s) {
  SimParams params;
  params.vehicle.kind = "multirotor";
  params.vehicle.multirotor.speed_mps = 4.0;
  params.vehicle.multirotor.yaw_at_corners = false;
  params.vehicle.altitude_agl_m = 2.0;
  params.start.at_mission_altitude = true;
  params.route.waypoints = {{20.0, 0.0}, {20.0, 20.0}};
  params.truth.rate_hz = 400.0;
  params.truth.nav_rate_hz = 0.0;
  params.sensors.rangefinder.enabled = false;
  params.sensors.barometer.enabled = false;
  params.sensors.ahrs.estimator = "ideal";
  params.sensors.gps.model.denied_after_s = denied_after_s;
  params.guidance.source = source;
  return params;
}

struct Flight {
  std::shared_ptr<terrain::ArenaWorld> world =
      std::make_shared<terrain::ArenaWorld>(terrain::ArenaParams{});
  core::LocalNedFrame frame{core::geodeticFromDegrees(53.0, -2.0, 80.0)};
  Simulator simulator;
  std::vector<WaypointEvent> events;
  explicit Flight(const SimParams& params) : simulator(params, world, frame) {}

  // Flies to the end; every 20 ms a fix `error` off the truth (from the step's truth).
  void fly(const Eigen::Vector3d& error) {
    int step = 0;
    while (!simulator.finished()) {
      const SimOutput out = simulator.step();
      if (out.waypoint) events.push_back(*out.waypoint);
      if (step++ % 8 == 0) simulator.positionFix(out.truth.utime, out.truth.p_ned_m + error);
    }
  }
};

// On the truth the fixes change nothing: the vehicle stops on each waypoint.
TEST(GuidanceTest, OnTheTruthTheFixesAreIgnored) {
  Flight flight(squareLeg("truth", -1.0));
  flight.fly(Eigen::Vector3d(3.0, -4.0, 0.0));
  ASSERT_EQ(flight.events.size(), 2u);
  for (const WaypointEvent& e : flight.events) {
    EXPECT_EQ(e.source, "truth");
    EXPECT_NEAR((e.true_ned_m - e.waypoint_ned_m).norm(), 0.0, 1e-6);
    EXPECT_NEAR((e.believed_ned_m - e.true_ned_m).norm(), 0.0, 1e-12);
  }
  EXPECT_EQ(flight.events[1].index, 1);
  EXPECT_EQ(flight.events[1].count, 2);
}

// On a source 3 m north and 4 m west of the truth from the start (no denial):
// it stops where it believes the waypoints are, so truly 5 m from each, at
// (17, 4) and (17, 24) m, and reports the 5 m. (Within its acceptance radius
// it brakes to a stop on the profile that ends on the waypoint: within a few
// mm of it, not exactly on it.)
TEST(GuidanceTest, OnASourceTheTruthEndsOffByItsError) {
  Flight flight(squareLeg("nav", -1.0));
  const Eigen::Vector3d error(3.0, -4.0, 0.0);
  flight.fly(error);
  ASSERT_EQ(flight.events.size(), 2u);
  for (const WaypointEvent& e : flight.events) {
    EXPECT_EQ(e.source, "nav");
    EXPECT_NEAR((e.believed_ned_m - e.waypoint_ned_m).norm(), 0.0, 0.005);
    EXPECT_NEAR((e.true_ned_m - e.believed_ned_m).norm(), 5.0, 1e-6);
  }
  EXPECT_NEAR(flight.events[1].true_ned_m.x(), 17.0, 0.005);
  EXPECT_NEAR(flight.events[1].true_ned_m.y(), 24.0, 0.005);
}

// With the GPS denied after 3 s, the first waypoint (reached at 5.3 s) is
// already on the source; with the denial after 30 s, neither is.
TEST(GuidanceTest, TheSourceTakesOverAtTheDenial) {
  Flight late(squareLeg("vo_feature", 30.0));
  late.fly(Eigen::Vector3d(3.0, -4.0, 0.0));
  ASSERT_EQ(late.events.size(), 2u);
  EXPECT_EQ(late.events[0].source, "truth");
  EXPECT_EQ(late.events[1].source, "truth");
  Flight early(squareLeg("vo_feature", 3.0));
  early.fly(Eigen::Vector3d(3.0, -4.0, 0.0));
  ASSERT_EQ(early.events.size(), 2u);
  EXPECT_EQ(early.events[0].source, "vo_feature");
  EXPECT_NEAR((early.events[0].true_ned_m - early.events[0].waypoint_ned_m).norm(), 5.0, 0.005);
}

// A fix for a time the simulator no longer holds (older than 5 s) or not yet
// reached is ignored.
TEST(GuidanceTest, FixesOutsideTheRecentTruthAreIgnored) {
  Flight flight(squareLeg("nav", -1.0));
  for (int i = 0; i < 2400; ++i) flight.simulator.step();  // 6 s
  flight.simulator.positionFix(0, Eigen::Vector3d(100.0, 100.0, 0.0));
  flight.simulator.positionFix(60'000'000, Eigen::Vector3d(100.0, 100.0, 0.0));
  while (!flight.simulator.finished()) {
    const SimOutput out = flight.simulator.step();
    if (out.waypoint) flight.events.push_back(*out.waypoint);
  }
  ASSERT_FALSE(flight.events.empty());
  EXPECT_NEAR((flight.events.back().true_ned_m - flight.events.back().waypoint_ned_m).norm(), 0.0,
              1e-6);
}

}  // namespace
}  // namespace nadir::sim
