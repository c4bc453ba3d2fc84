// The simulator's rover under external control: commands take effect at their
// own time, the speed follows at the rover's acceleration, a silent controller
// brings it to a stop (the failsafe), and the run ends once it stands still.

#include <gtest/gtest.h>

#include <memory>

#include "core/geodesy.h"
#include "nodes/sim/simulator.h"
#include "terrain/arena_world.h"

namespace nadir::sim {
namespace {

SimParams roverParams() {
  SimParams params;
  params.duration_s = 5.0;
  params.vehicle.kind = "rover";
  params.vehicle.control = "external";
  params.vehicle.command_timeout_s = 0.25;
  params.vehicle.rover.max_acceleration_mps2 = 6.0;
  params.vehicle.rover.max_deceleration_mps2 = 8.0;
  params.truth.rate_hz = 400.0;
  params.truth.nav_rate_hz = 0.0;
  params.sensors.rangefinder.enabled = false;
  params.sensors.gps.enabled = false;
  params.sensors.barometer.enabled = false;
  params.sensors.ahrs.estimator = "ideal";
  return params;
}

struct RoverRun {
  std::shared_ptr<terrain::ArenaWorld> world =
      std::make_shared<terrain::ArenaWorld>(terrain::ArenaParams{});
  core::LocalNedFrame frame{core::geodeticFromDegrees(53.0, -2.0, 80.0)};
  Simulator simulator;
  explicit RoverRun(const SimParams& params) : simulator(params, world, frame) {}

  // Steps until sim time t_s (from the start); returns the last output.
  SimOutput until(double t_s) {
    SimOutput out;
    do {
      out = simulator.step();
    } while (out.truth.utime - simulator.startUtime() < static_cast<std::int64_t>(t_s * 1e6));
    return out;
  }
  std::int64_t at(double t_s) const {
    return simulator.startUtime() + static_cast<std::int64_t>(t_s * 1e6);
  }
};

// Commanded 1 m/s from 0.5 s on, every 5 ms: 6 m/s^2 reach it in 1/6 s over
// 1/12 m, so at 1.5 s the rover is 1/12 + (1 - 1/6) = 0.9167 m north.
TEST(ExternalControlTest, CommandsTakeEffectAtTheirTime) {
  RoverRun run(roverParams());
  EXPECT_TRUE(run.simulator.externalControl());
  for (double t = 0.5; t < 3.0; t += 0.005) run.simulator.drive({run.at(t), 0.0, 1.0});
  EXPECT_NEAR(run.until(0.49).truth.p_ned_m.norm(), 0.0, 1e-12);
  const SimOutput out = run.until(1.5);
  EXPECT_NEAR(out.truth.p_ned_m.x(), 1.0 / 12.0 + (1.5 - 0.5 - 1.0 / 6.0), 0.01);
  EXPECT_NEAR(out.truth.p_ned_m.y(), 0.0, 1e-9);
  EXPECT_NEAR(out.truth.v_ned_mps.norm(), 1.0, 1e-9);
}

// The last command at 0.995 s: stale from 1.245 s, then braking at 8 m/s^2
// from 1 m/s stops the rover by 1.37 s; it stands still after.
TEST(ExternalControlTest, ASilentControllerStopsTheRover) {
  RoverRun run(roverParams());
  for (double t = 0.0; t < 0.999; t += 0.005) run.simulator.drive({run.at(t), 0.0, 1.0});
  EXPECT_NEAR(run.until(1.24).truth.v_ned_mps.norm(), 1.0, 1e-9);
  const double north_at_stop = run.until(1.40).truth.p_ned_m.x();
  EXPECT_NEAR(run.until(1.40).truth.v_ned_mps.norm(), 0.0, 1e-9);
  EXPECT_NEAR(run.until(2.0).truth.p_ned_m.x(), north_at_stop, 1e-9);
  // Standing still for a second after moving ends the run.
  run.until(2.3);
  EXPECT_FALSE(run.simulator.finished());
  run.until(2.45);
  EXPECT_TRUE(run.simulator.finished());
}

// Steering right at 0.2 rad on a 0.3 m wheelbase turns the heading east at
// v tan(0.2) / 0.3 rad/s.
TEST(ExternalControlTest, SteeringTurnsRight) {
  RoverRun run(roverParams());
  for (double t = 0.0; t < 3.0; t += 0.005) run.simulator.drive({run.at(t), 0.2, 1.0});
  const SimOutput out = run.until(2.0);
  EXPECT_GT(out.truth.p_ned_m.y(), 0.3);
  EXPECT_NEAR(out.truth.omega_body_rps.z(), std::tan(0.2) / 0.3, 1e-9);
}

TEST(ExternalControlTest, ParametersThatCannotWorkAreNamed) {
  SimParams no_duration = roverParams();
  no_duration.duration_s = 0.0;
  EXPECT_THROW(RoverRun{no_duration}, core::ParamError);
  try {
    RoverRun run(no_duration);
  } catch (const core::ParamError& error) {
    EXPECT_NE(std::string(error.what()).find("duration_s"), std::string::npos) << error.what();
  }
  SimParams aircraft = roverParams();
  aircraft.vehicle.kind = "fixed_wing";
  try {
    RoverRun run(aircraft);
    FAIL() << "external control of an aircraft was accepted";
  } catch (const core::ParamError& error) {
    EXPECT_NE(std::string(error.what()).find("vehicle.control"), std::string::npos) << error.what();
  }
  SimParams route = roverParams();
  route.vehicle.control = "route";
  route.route.waypoints = {{10.0, 0.0}};
  RoverRun following(route);
  EXPECT_THROW(following.simulator.drive({0, 0.0, 1.0}), std::logic_error);
}

}  // namespace
}  // namespace nadir::sim
