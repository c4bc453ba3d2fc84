// Scenarios: the built-in ones load and fly as the thesis and McConville et al. (2020)
// describe them; bad scenarios are refused with the key named; runs are
// deterministic; a recorded flight comes back out of the truth stream.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "core/bus.h"
#include "core/frames.h"
#include "lcmtypes/bus_io.h"
#include "nodes/scenario.h"
#include "nodes/sim/sim_node.h"
#include "nodes/sim/simulator.h"
#include "terrain/world_factory.h"

namespace nadir::nodes {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

struct Flown {
  std::vector<sim::VehicleState> truth;
  std::vector<sim::SimOutput> outputs;
  double track_length_m = 0.0;
  double horizontal_track_length_m = 0.0;
};

// Flies a scenario to its end (sensors as configured), keeping every step.
Flown fly(const ScenarioParams& scenario, bool keep_outputs = false) {
  const terrain::BuiltWorld built = terrain::makeWorld(scenario.world);
  const core::LocalNedFrame frame(built.origin);
  sim::Simulator simulator(scenario.sim, built.world, frame,
                           sim::loadFlight(scenario.sim.flight, frame));
  Flown flown;
  while (!simulator.finished()) {
    sim::SimOutput output = simulator.step();
    if (!flown.truth.empty()) {
      const Eigen::Vector3d step = output.truth.p_ned_m - flown.truth.back().p_ned_m;
      flown.track_length_m += step.norm();
      flown.horizontal_track_length_m += step.head<2>().norm();
    }
    flown.truth.push_back(output.truth);
    if (keep_outputs) flown.outputs.push_back(std::move(output));
  }
  return flown;
}

ScenarioParams withoutSensors(ScenarioParams scenario) {
  scenario.sim.sensors.imu.enabled = false;
  scenario.sim.sensors.rangefinder.enabled = false;
  scenario.sim.sensors.gps.enabled = false;
  scenario.sim.sensors.barometer.enabled = false;
  scenario.sim.sensors.magnetometer.enabled = false;
  scenario.sim.sensors.ahrs.estimator = "ideal";
  return scenario;
}

template <class F>
std::string paramErrorOf(F&& f) {
  try {
    f();
  } catch (const core::ParamError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a ParamError";
  return "";
}

std::string writeTemp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "nadir_scenario_" + name;
  std::ofstream(path) << text;
  return path;
}

// The scenarios the issue names are all built in and load with their documented values.
TEST(Scenario, BuiltInsLoad) {
  const std::vector<std::string> names = builtinScenarioNames();
  for (const char* name : {"thesis-oscillating", "thesis-atterbury", "box", "cloverleaf", "grid",
                           "scamp-rectangle", "default"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
    ScenarioParams scenario;
    ASSERT_NO_THROW(scenario = loadScenario(name)) << name;
    EXPECT_FALSE(scenario.description.empty()) << name;
  }
  const ScenarioParams thesis = loadScenario("thesis-oscillating");
  EXPECT_EQ(thesis.camera.camera.width, 1280);
  EXPECT_EQ(thesis.camera.camera.height, 960);
  EXPECT_DOUBLE_EQ(thesis.camera.camera.hfov_deg, 84.872);
  EXPECT_DOUBLE_EQ(thesis.camera.fps, 31.0);
  EXPECT_EQ(loadScenario("box").sim.vehicle.altitude_agl_m, 450.0);
  EXPECT_EQ(loadScenario("cloverleaf").sim.vehicle.altitude_agl_m, 400.0);
  EXPECT_EQ(loadScenario("grid").sim.vehicle.altitude_agl_m, 100.0);
  const ScenarioParams scamp = loadScenario("scamp-rectangle");
  EXPECT_EQ(scamp.camera.camera.width, 256);
  EXPECT_EQ(scamp.camera.camera.height, 256);
  EXPECT_DOUBLE_EQ(scamp.camera.fps, 200.0);
  ASSERT_EQ(scamp.targets.count("start_corner"), 1u);
  EXPECT_EQ(scamp.targets.at("start_corner").kind, "concentric");
  // The thesis's conditions: every camera effect on, the estimated attitude, low texture.
  const ScenarioParams atterbury = loadScenario("thesis-atterbury");
  const render::CameraParams& camera = atterbury.camera.camera;
  EXPECT_TRUE(camera.motion_blur && camera.rolling_shutter && camera.vignetting &&
              camera.auto_exposure && camera.response_curve);
  EXPECT_GT(camera.read_noise_counts, 0.0);
  EXPECT_GT(atterbury.camera.timestamp_jitter_s, 0.0);
  EXPECT_EQ(atterbury.sim.sensors.ahrs.estimator, "complementary");
  EXPECT_EQ(atterbury.sim.vehicle.altitude_agl_m, 300.0);
}

// The virtual checkerboard's scenario: the camera (1280 x 960, 84.872 deg,
// k1 = -0.20, k2 = 0.05, noise on) over a 9x6 board; not ground to fly over.
TEST(Scenario, CalibrationScenarioIsABoard) {
  const ScenarioParams calibration = loadScenario("calibration");
  EXPECT_EQ(calibration.world.kind, "checkerboard");
  EXPECT_EQ(calibration.world.checkerboard.inner_cols, 9);
  EXPECT_EQ(calibration.world.checkerboard.inner_rows, 6);
  EXPECT_DOUBLE_EQ(calibration.world.checkerboard.square_m, 0.025);
  EXPECT_EQ(calibration.camera.camera.width, 1280);
  EXPECT_DOUBLE_EQ(calibration.camera.camera.distortion[0], -0.20);
  EXPECT_DOUBLE_EQ(calibration.camera.camera.distortion[1], 0.05);
  EXPECT_GT(calibration.camera.camera.read_noise_counts, 0.0);
  EXPECT_EQ(calibration.calibration.views, 60);
  try {
    terrain::requireFlightWorld(calibration.world);
    ADD_FAILURE() << "a checkerboard world was taken for ground to fly over";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("nadir calib --virtual"), std::string::npos);
  }
  EXPECT_NO_THROW(terrain::requireFlightWorld(loadScenario("default").world));
}

// The effective scenario a run writes (scenario.yaml) loads back to the same
// parameters, for every built-in scenario.
TEST(Scenario, FormattedScenarioLoadsBack) {
  const std::filesystem::path folder =
      std::filesystem::path(::testing::TempDir()) / "nadir_scenario_formatted";
  std::filesystem::create_directories(folder);
  for (const std::string& name : builtinScenarioNames()) {
    ScenarioParams original = loadScenario(name);
    const std::string text = core::formatParamsOf(original);
    const std::filesystem::path path = folder / (name + ".yaml");
    std::ofstream(path) << text;
    ScenarioParams copy;
    ASSERT_NO_THROW(copy = loadScenario(path.string())) << name;
    EXPECT_EQ(copy.targets.size(), original.targets.size()) << name;
    EXPECT_EQ(copy.sim.vehicle.altitude_agl_m, original.sim.vehicle.altitude_agl_m) << name;
  }
}

// The experiment axes are keys of every fixed-wing scenario and reach the models.
TEST(Scenario, ExperimentAxesOverride) {
  for (const char* name : {"thesis-oscillating", "box", "cloverleaf", "grid", "default"}) {
    const ScenarioParams scenario =
        loadScenario(name, {"vehicle.airspeed_mps=10", "vehicle.max_roll_rate_dps=65",
                            "vehicle.altitude_agl_m=250", "camera.fps=5"});
    EXPECT_EQ(scenario.sim.vehicle.kind, "fixed_wing") << name;
    EXPECT_EQ(scenario.sim.vehicle.fixed_wing.airspeed_mps, 10.0) << name;
    EXPECT_EQ(scenario.sim.vehicle.fixed_wing.max_roll_rate_dps, 65.0) << name;
    EXPECT_EQ(scenario.sim.vehicle.altitude_agl_m, 250.0) << name;
    EXPECT_EQ(scenario.allCameras().at("down").fps, 5.0) << name;
  }
}

// Thesis section 3.3.2: a 3.3 km trajectory (+-10 %) at every corner of the experiment grid,
// at mission altitude and airspeed at the end; up to 250 m AGL the climb ends by waypoint 3
// and the leg to waypoint 5 is level at 20 m/s (from 400 m the climb takes most of that leg).
TEST(Scenario, ThesisOscillatingIs3point3Km) {
  for (const double airspeed : {10.0, 25.0}) {
    for (const double roll_rate : {25.0, 65.0}) {
      for (const double altitude : {50.0, 250.0, 400.0}) {
        SCOPED_TRACE(std::to_string(airspeed) + " m/s, " + std::to_string(roll_rate) + " deg/s, " +
                     std::to_string(altitude) + " m");
        const ScenarioParams scenario = withoutSensors(loadScenario(
            "thesis-oscillating", {"vehicle.airspeed_mps=" + std::to_string(airspeed),
                                   "vehicle.max_roll_rate_dps=" + std::to_string(roll_rate),
                                   "vehicle.altitude_agl_m=" + std::to_string(altitude)}));
        const Flown flown = fly(scenario);
        EXPECT_NEAR(flown.track_length_m, 3300.0, 330.0);
        // Level leg: flying south at 20 m/s when passing 800 m south of the start.
        const auto on_leg = std::find_if(flown.truth.begin(), flown.truth.end(),
                                         [](const auto& s) { return s.p_ned_m.x() < -800.0; });
        ASSERT_NE(on_leg, flown.truth.end());
        if (altitude <= 250.0) {
          EXPECT_NEAR(on_leg->v_ned_mps.head<2>().norm(), 20.0, 0.05);
        }
        // End: mission airspeed (no wind) and altitude (above the start's ground).
        const sim::VehicleState& end = flown.truth.back();
        EXPECT_NEAR(end.v_ned_mps.norm(), airspeed, 0.05);
        EXPECT_NEAR(-end.p_ned_m.z() - (-flown.truth.front().p_ned_m.z() - 30.0), altitude, 1.0);
      }
    }
  }
}

// The fixed-wing of a scenario keeps its roll-rate and bank limits through the whole pattern.
TEST(Scenario, ThesisOscillatingRespectsRollLimits) {
  const ScenarioParams scenario = withoutSensors(loadScenario(
      "thesis-oscillating", {"vehicle.max_roll_rate_dps=25", "vehicle.max_bank_deg=40"}));
  const Flown flown = fly(scenario);
  const double dt_s = 1.0 / scenario.sim.truth.rate_hz;
  double max_bank = 0.0, max_roll_rate = 0.0;
  for (std::size_t i = 1; i < flown.truth.size(); ++i) {
    const double roll = core::rpyFromQuaternion(flown.truth[i].q_world_body).roll_rad;
    const double previous = core::rpyFromQuaternion(flown.truth[i - 1].q_world_body).roll_rad;
    max_bank = std::max(max_bank, std::abs(roll));
    max_roll_rate = std::max(max_roll_rate, std::abs(roll - previous) / dt_s);
  }
  EXPECT_LE(max_bank, 40.0 * kDeg + 1e-9);
  EXPECT_GT(max_bank, 39.0 * kDeg);  // the oscillation does need the full bank
  EXPECT_LE(max_roll_rate, 25.0 * kDeg * (1.0 + 1e-6));
}

// McConville et al. (2020): four laps of a 50 m x 25 m rectangle (4 x 150 m +- 2 %) at 5 m above
// the ground, with a 90 deg yaw at every corner.
TEST(Scenario, ScampRectangleIsFourLapsWithRightAngleYaws) {
  const ScenarioParams scenario = withoutSensors(loadScenario("scamp-rectangle"));
  const Flown flown = fly(scenario);
  EXPECT_NEAR(flown.horizontal_track_length_m, 600.0, 12.0);
  // The heading of each leg, read while moving; consecutive legs differ by 90 deg.
  std::vector<double> leg_yaws_deg;
  bool counted = false;
  terrain::BuiltWorld built = terrain::makeWorld(scenario.world);
  for (const sim::VehicleState& state : flown.truth) {
    const double speed = state.v_ned_mps.norm();
    if (speed > 2.9 && !counted) {
      leg_yaws_deg.push_back(core::rpyFromQuaternion(state.q_world_body).yaw_rad / kDeg);
      counted = true;
    }
    if (speed < 0.1) counted = false;
    if (speed > 2.9) {
      // Terrain following: 5 m above the ground within the relief between corners.
      EXPECT_NEAR(terrain::heightAboveGround_m(*built.world, state.p_ned_m.x(), state.p_ned_m.y(),
                                               state.p_ned_m.z()),
                  5.0, 1.5);
    }
  }
  ASSERT_EQ(leg_yaws_deg.size(), 16u);
  for (std::size_t i = 1; i < leg_yaws_deg.size(); ++i) {
    const double step = std::remainder(leg_yaws_deg[i] - leg_yaws_deg[i - 1], 360.0);
    EXPECT_NEAR(std::abs(step), 90.0, 0.5) << "leg " << i;
  }
}

// Two runs of one scenario with one seed give identical truth and sensor streams;
// another IMU seed changes the IMU and nothing else.
TEST(Scenario, SameSeedSameStreams) {
  ScenarioParams scenario = loadScenario(
      "default", {"duration_s=20", "vehicle.turbulence_mps=1.5", "sensors.gps.outages_s=[5, 8]"});
  const Flown a = fly(scenario, true);
  const Flown b = fly(scenario, true);
  ASSERT_EQ(a.outputs.size(), b.outputs.size());
  ASSERT_EQ(a.outputs.size(), 20u * 400u + 1u);
  const auto same = [](const sim::SimOutput& x, const sim::SimOutput& y) {
    return x.truth.p_ned_m == y.truth.p_ned_m &&
           x.truth.q_world_body.coeffs() == y.truth.q_world_body.coeffs() &&
           x.imu.has_value() == y.imu.has_value() &&
           (!x.imu || (x.imu->angular_velocity_rps == y.imu->angular_velocity_rps &&
                       x.imu->linear_acceleration_mps2 == y.imu->linear_acceleration_mps2)) &&
           x.gps.has_value() == y.gps.has_value() &&
           (!x.gps || (x.gps->lat_rad == y.gps->lat_rad && x.gps->fix == y.gps->fix)) &&
           x.range.has_value() == y.range.has_value() &&
           (!x.range || x.range->range_m == y.range->range_m) &&
           x.baro.has_value() == y.baro.has_value() &&
           (!x.baro || x.baro->altitude_m == y.baro->altitude_m);
  };
  for (std::size_t i = 0; i < a.outputs.size(); ++i) {
    ASSERT_TRUE(same(a.outputs[i], b.outputs[i])) << "step " << i;
  }
  scenario.sim.sensors.imu.model.seed += 1;
  const Flown c = fly(scenario, true);
  int imu_differs = 0;
  for (std::size_t i = 0; i < a.outputs.size(); ++i) {
    EXPECT_EQ(a.outputs[i].truth.p_ned_m, c.outputs[i].truth.p_ned_m);
    if (a.outputs[i].imu &&
        a.outputs[i].imu->angular_velocity_rps != c.outputs[i].imu->angular_velocity_rps) {
      ++imu_differs;
    }
  }
  EXPECT_GT(imu_differs, 0);
}

// Sensors publish at their configured rates in sim time.
TEST(Scenario, SensorRates) {
  const ScenarioParams scenario = loadScenario("default", {"duration_s=10"});
  const Flown flown = fly(scenario, true);
  int imu = 0, range = 0, gps = 0, baro = 0, mag = 0, nav = 0;
  for (const sim::SimOutput& output : flown.outputs) {
    imu += output.imu.has_value();
    mag += output.mag.has_value();
    range += output.range.has_value();
    gps += output.gps.has_value();
    baro += output.baro.has_value();
    nav += output.nav.has_value();
  }
  EXPECT_EQ(imu, 200 * 10 + 1);
  EXPECT_EQ(range, 50 * 10 + 1);
  EXPECT_EQ(gps, 5 * 10 + 1);
  EXPECT_EQ(baro, 50 * 10 + 1);
  EXPECT_EQ(mag, 50 * 10 + 1);
  EXPECT_EQ(nav, 50 * 10 + 1);
}

// NAV_* are the flight controller's estimate by default: near the truth (a
// few tenths of a degree of tilt, a few degrees of heading, metres of
// position) but not the truth; with sensors.ahrs.estimator=ideal, the truth.
TEST(Scenario, NavIsTheFlightControllersEstimateUnlessIdeal) {
  constexpr double kDeg = 180.0 / std::numbers::pi;
  for (const bool ideal : {false, true}) {
    ScenarioParams scenario = loadScenario("default", {"duration_s=30"});
    if (ideal) scenario.sim.sensors.ahrs.estimator = "ideal";
    const Flown flown = fly(scenario, true);
    const core::LocalNedFrame frame(terrain::makeWorld(scenario.world).origin);
    double tilt2 = 0.0, heading2 = 0.0, position2 = 0.0;
    int n = 0;
    for (const sim::SimOutput& output : flown.outputs) {
      if (!output.nav) continue;
      const Eigen::Quaterniond& q_truth = output.truth.q_world_body;
      const Eigen::Quaterniond& q_nav = output.nav->attitude.q_world_body;
      const Eigen::Vector3d down_truth = q_truth.conjugate() * Eigen::Vector3d::UnitZ();
      const Eigen::Vector3d down_nav = q_nav.conjugate() * Eigen::Vector3d::UnitZ();
      tilt2 += std::pow(std::acos(std::clamp(down_truth.dot(down_nav), -1.0, 1.0)) * kDeg, 2);
      heading2 += std::pow(
          std::remainder(output.nav->attitude.yaw_rad - core::rpyFromQuaternion(q_truth).yaw_rad,
                         2 * std::numbers::pi) *
              kDeg,
          2);
      const nadir::msg::GeodeticPosition& p = output.nav->position;
      position2 += (frame.nedFromGeodetic({p.lat_rad, p.lon_rad, p.alt_m}) - output.truth.p_ned_m)
                       .squaredNorm();
      ++n;
    }
    ASSERT_EQ(n, 50 * 30 + 1);
    const double tilt_rms = std::sqrt(tilt2 / n), heading_rms = std::sqrt(heading2 / n);
    const double position_rms = std::sqrt(position2 / n);
    if (ideal) {
      EXPECT_LT(tilt_rms, 1e-5);
      EXPECT_LT(heading_rms, 1e-6);
      EXPECT_LT(position_rms, 1e-6);
    } else {
      EXPECT_GT(tilt_rms, 0.05);
      EXPECT_LT(tilt_rms, 1.5);
      EXPECT_GT(heading_rms, 0.2);
      EXPECT_LT(heading_rms, 5.0);
      EXPECT_GT(position_rms, 0.1);
      EXPECT_LT(position_rms, 5.0);
    }
  }
}

// The estimator needs its IMU and magnetometer; without them the key is named.
TEST(Scenario, AnEstimatorWithoutItsSensorsIsRefused) {
  const ScenarioParams scenario = loadScenario("default", {"sensors.magnetometer.enabled=false"});
  const std::string message = paramErrorOf([&] { fly(scenario); });
  EXPECT_NE(message.find("sensors.ahrs.estimator"), std::string::npos) << message;
  EXPECT_NE(message.find("sensors.magnetometer.enabled"), std::string::npos) << message;
}

// An unknown key is refused with the file, line and key named, and the keys known there.
TEST(Scenario, UnknownKeyIsRefused) {
  const std::string path =
      writeTemp("unknown.yaml", "vehicle:\n  kind: fixed_wing\n  airsped_mps: 20\n");
  const std::string message = paramErrorOf([&] { loadScenario(path); });
  EXPECT_NE(message.find(path + ":3: vehicle.airsped_mps: unknown key"), std::string::npos)
      << message;
  EXPECT_NE(message.find("airspeed_mps"), std::string::npos) << message;
  const std::string override_message =
      paramErrorOf([&] { loadScenario("default", {"vehicle.top_speed=3"}); });
  EXPECT_NE(override_message.find("vehicle.top_speed: unknown key"), std::string::npos)
      << override_message;
}

// A negative speed is refused, as the cruise airspeed and as a leg speed.
TEST(Scenario, NegativeSpeedIsRefused) {
  std::string message =
      paramErrorOf([&] { loadScenario("thesis-oscillating", {"vehicle.airspeed_mps=-5"}); });
  EXPECT_NE(message.find("vehicle.airspeed_mps: -5 is out of range"), std::string::npos) << message;
  message = paramErrorOf([&] { loadScenario("box", {"route.leg_speeds_mps=[20, -1, 20, 20]"}); });
  EXPECT_NE(message.find("route.leg_speeds_mps: -1 is out of range"), std::string::npos) << message;
  message =
      paramErrorOf([&] { loadScenario("scamp-rectangle", {"vehicle.multirotor.speed_mps=-3"}); });
  EXPECT_NE(message.find("vehicle.multirotor.speed_mps: -3 is out of range"), std::string::npos)
      << message;
}

// Waypoints closer than the aircraft can turn between, a speed list of the wrong length and
// an empty route are refused when the simulator is built, naming the key.
TEST(Scenario, UnflyableRoutesAreRefused) {
  const auto build = [](const ScenarioParams& scenario) {
    const terrain::BuiltWorld built = terrain::makeWorld(scenario.world);
    sim::Simulator simulator(scenario.sim, built.world, core::LocalNedFrame(built.origin));
  };
  // 25 m/s at 45 deg: r = 63.73 m; 90 deg turns at both ends of a 100 m leg need 127.5 m.
  std::string message = paramErrorOf(
      [&] { build(loadScenario("box", {"route.waypoints=[[1000, 0], [1000, 100], [0, 100]]"})); });
  EXPECT_NE(message.find("route.waypoints: waypoint 2 is 100.0 m"), std::string::npos) << message;
  EXPECT_NE(message.find("need 127.5 m at 25.0 m/s and 45.0 deg bank"), std::string::npos)
      << message;
  message = paramErrorOf([&] { build(loadScenario("box", {"route.leg_speeds_mps=[20, 20]"})); });
  EXPECT_NE(message.find("route.leg_speeds_mps: 2 speeds for 4 waypoints"), std::string::npos)
      << message;
  message = paramErrorOf([&] { build(loadScenario("box", {"route.waypoints=[]"})); });
  EXPECT_NE(message.find("route.waypoints: no waypoints"), std::string::npos) << message;
}

// An unknown scenario name lists the built-in ones.
TEST(Scenario, UnknownNameListsBuiltIns) {
  const std::string message = paramErrorOf([] { loadScenario("thesis-oscilating"); });
  EXPECT_NE(message.find("thesis-oscilating"), std::string::npos) << message;
  EXPECT_NE(message.find("thesis-oscillating"), std::string::npos) << message;
}

// Waypoints given geodetically land where the local frame puts those coordinates.
TEST(Scenario, GeodeticWaypoints) {
  ScenarioParams scenario = loadScenario("default");
  const core::LocalNedFrame frame(core::geodeticFromDegrees(
      scenario.world.origin_lat_deg, scenario.world.origin_lon_deg, scenario.world.origin_alt_m));
  // About 1 km north and 500 m east of the origin: 1/111.2 deg of latitude per km.
  scenario.sim.route.frame = "geodetic";
  scenario.sim.route.waypoints = {{47.009, 8.0}, {47.009, 8.0066}};
  const terrain::BuiltWorld built = terrain::makeWorld(scenario.world);
  const sim::ResolvedRoute route = sim::resolveRoute(scenario.sim, *built.world, frame);
  ASSERT_EQ(route.waypoints.size(), 2u);
  EXPECT_NEAR(route.waypoints[0].p_ned_m.x(), 1000.7, 1.0);
  EXPECT_NEAR(route.waypoints[0].p_ned_m.y(), 0.0, 0.1);
  EXPECT_NEAR(route.waypoints[1].p_ned_m.y(), 0.0066 * 111320.0 * std::cos(47.009 * kDeg), 2.0);
}

// Relative file paths in a scenario are relative to the scenario's folder.
TEST(Scenario, RelativePathsFollowTheFile) {
  const std::filesystem::path folder =
      std::filesystem::path(::testing::TempDir()) / "nadir_scenario_folder";
  std::filesystem::create_directories(folder);
  std::ofstream(folder / "replay.yaml") << "flight:\n  path: flights/one.csv\n";
  const ScenarioParams scenario = loadScenario((folder / "replay.yaml").string());
  EXPECT_EQ(scenario.sim.flight.path, (folder / "flights/one.csv").string());
}

// A files world centres on its DEM unless the scenario gives an origin:
// giving origin_lat_deg/lon_deg (in the file or with --set) is enough;
// origin_at_dem_centre given as well wins (so a formatted scenario, which
// writes both, loads back as it was).
TEST(Scenario, AGivenOriginIsUsedForAFilesWorld) {
  constexpr double kDeg = std::numbers::pi / 180.0;
  const std::filesystem::path folder =
      std::filesystem::path(::testing::TempDir()) / "nadir_scenario_origin";
  std::filesystem::create_directories(folder);
  const std::string dem = std::string(NADIR_TEST_DATA_DIR) + "/terrain/zion_srtm.tif";
  const auto write = [&](const std::string& name, const std::string& world_lines) {
    const std::filesystem::path path = folder / name;
    std::ofstream(path) << "world:\n  kind: files\n  dem_path: " << dem << "\n" << world_lines;
    return path.string();
  };
  // zion_srtm.tif's centre: lat (37.1321 + 37.5129) / 2, lon (-113.2396 - 112.8521) / 2.
  const core::Geodetic centre = scenarioOrigin(loadScenario(write("centre.yaml", "")));
  EXPECT_NEAR(centre.lat_rad / kDeg, 37.3225, 1e-3);
  EXPECT_NEAR(centre.lon_rad / kDeg, -113.04585, 1e-3);

  const std::string given =
      write("given.yaml", "  origin_lat_deg: 37.25\n  origin_lon_deg: -113.1\n");
  const core::Geodetic at = scenarioOrigin(loadScenario(given));
  EXPECT_NEAR(at.lat_rad / kDeg, 37.25, 1e-12);
  EXPECT_NEAR(at.lon_rad / kDeg, -113.1, 1e-12);

  const core::Geodetic set = scenarioOrigin(loadScenario(
      write("set.yaml", ""), {"world.origin_lat_deg=37.2", "world.origin_lon_deg=-113"}));
  EXPECT_NEAR(set.lat_rad / kDeg, 37.2, 1e-12);

  const core::Geodetic both = scenarioOrigin(
      loadScenario(write("both.yaml", "  origin_lat_deg: 37.25\n  origin_at_dem_centre: true\n")));
  EXPECT_NEAR(both.lat_rad / kDeg, 37.3225, 1e-3);
}

// A scenario without a start time starts on 2024-06-21 at 10:00 local mean
// solar time at its origin (47 N, 8 E: 10:00 - 8 / 15 h = 09:28 UTC), and the
// procedural world's sun stands where it is then: hour angle -30 deg minus the
// equation of time's 0.4 deg, declination 23.44 deg, so elevation
// asin(sin 47 sin 23.44 + cos 47 cos 23.44 cos 30.4) = 56.16 deg and azimuth
// 123.5 deg (worked out by hand). Given sun angles are kept; a start at night
// or text that is no UTC time is refused naming time.start_utc.
TEST(Scenario, StartTimeAndTheSunFromIt) {
  const std::filesystem::path folder =
      std::filesystem::path(::testing::TempDir()) / "nadir_scenario_start";
  std::filesystem::create_directories(folder);
  const std::string path = (folder / "alps.yaml").string();
  std::ofstream(path) << "world:\n  kind: procedural\n  origin_lat_deg: 47\n  origin_lon_deg: 8\n";
  const ScenarioParams alps = loadScenario(path);
  EXPECT_EQ(alps.time.start_utc, "2024-06-21T09:28:00Z");
  EXPECT_NEAR(alps.world.procedural.sun_elevation_deg, 56.16, 0.2);
  EXPECT_NEAR(alps.world.procedural.sun_azimuth_deg, 123.5, 0.5);

  const ScenarioParams given = loadScenario(path, {"world.procedural.sun_elevation_deg=30"});
  EXPECT_EQ(given.world.procedural.sun_elevation_deg, 30.0);
  EXPECT_EQ(given.world.procedural.sun_azimuth_deg, 150.0);

  const ScenarioParams builtin = loadScenario("default");
  EXPECT_EQ(builtin.world.procedural.sun_azimuth_deg, 150.0);
  EXPECT_EQ(builtin.world.procedural.sun_elevation_deg, 45.0);

  for (const std::string& start : {std::string("2024-06-21T23:00:00Z"), std::string("yesterday")}) {
    try {
      loadScenario(path, {"time.start_utc=" + start});
      ADD_FAILURE() << start << ": no error";
    } catch (const core::ParamError& e) {
      EXPECT_NE(std::string(e.what()).find("time.start_utc"), std::string::npos) << e.what();
    }
  }
}

// A real flight from a CSV comes back out of the POSE_TRUTH stream within the
// interpolation error: a 200 m circle at 20 m/s sampled at 10 Hz, replayed at 400 Hz.
TEST(Scenario, FlightCsvRoundTripsThroughTheTruthStream) {
  ScenarioParams scenario = loadScenario("default");
  const core::LocalNedFrame frame(core::geodeticFromDegrees(
      scenario.world.origin_lat_deg, scenario.world.origin_lon_deg, scenario.world.origin_alt_m));
  const double radius_m = 200.0, speed_mps = 20.0, omega = speed_mps / radius_m;
  const auto truthAt = [&](double t_s) {
    const double a = omega * t_s;
    sim::VehicleState s;
    s.p_ned_m = {radius_m * std::sin(a), radius_m * (1.0 - std::cos(a)), -150.0 - 0.5 * t_s};
    s.q_world_body = core::quaternionFromRpy({20.0 * kDeg, 2.0 * kDeg, a});
    return s;
  };
  std::string csv = "time_s,lat_deg,lon_deg,alt_m,roll_deg,pitch_deg,yaw_deg\n";
  char line[256];
  for (int i = 0; i <= 300; ++i) {
    const double t = 100.0 + 0.1 * i;
    const sim::VehicleState s = truthAt(t - 100.0);
    const core::Geodetic g = frame.geodeticFromNed(s.p_ned_m);
    const core::RollPitchYaw rpy = core::rpyFromQuaternion(s.q_world_body);
    std::snprintf(line, sizeof(line), "%.3f,%.10f,%.10f,%.4f,%.6f,%.6f,%.6f\n", t, g.lat_rad / kDeg,
                  g.lon_rad / kDeg, g.alt_m, rpy.roll_rad / kDeg, rpy.pitch_rad / kDeg,
                  rpy.yaw_rad / kDeg);
    csv += line;
  }
  scenario.sim.flight.path = writeTemp("circle.csv", csv);

  auto bus = core::openBus("memq://");
  std::vector<sim::VehicleState> received;
  auto subscription = msg::subscribe<msg::Pose>(
      *bus, "POSE_TRUTH", [&](const msg::Pose& pose) { received.push_back(pose); });
  const terrain::BuiltWorld built = terrain::makeWorld(scenario.world);
  sim::Simulator simulator(scenario.sim, built.world, frame,
                           sim::loadFlight(scenario.sim.flight, frame));
  sim::SimPublisher publisher(*bus, scenario.sim, simulator);
  while (!simulator.finished()) {
    publisher.publish(simulator.step());
    while (bus->handle(std::chrono::milliseconds(0))) {
    }
  }
  ASSERT_EQ(received.size(), 30u * 400u + 1u);
  EXPECT_EQ(received.front().utime, 100'000'000);
  EXPECT_EQ(received.back().utime, 130'000'000);
  // Chord error of linear interpolation on the circle: r (1 - cos(omega dt / 2)) = 2.5 mm;
  // attitude: the SLERP of two Euler-angle poses deviates from the Euler path by < 0.01 deg here.
  const double chord_error_m = radius_m * (1.0 - std::cos(omega * 0.1 / 2.0));
  double max_position_error = 0.0, max_angle_error = 0.0;
  for (const sim::VehicleState& state : received) {
    const sim::VehicleState expected = truthAt(core::secondsFromUtime(state.utime) - 100.0);
    max_position_error = std::max(max_position_error, (state.p_ned_m - expected.p_ned_m).norm());
    max_angle_error =
        std::max(max_angle_error,
                 Eigen::AngleAxisd(state.q_world_body.conjugate() * expected.q_world_body).angle());
  }
  EXPECT_LE(max_position_error, chord_error_m + 0.002);
  EXPECT_GT(max_position_error, 0.5 * chord_error_m);  // the interpolation is really exercised
  EXPECT_LE(max_angle_error, 0.01 * kDeg);
}

}  // namespace
}  // namespace nadir::nodes
