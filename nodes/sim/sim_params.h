#pragma once
// What nadir-sim simulates, as parameters: the vehicle, where it starts, the
// route it follows (or a recorded flight to replay), the truth stream and the
// sensors. A scenario (nodes/scenario.h) holds these at its top level, so that
// `--set vehicle.airspeed_mps=25` reaches FixedWingParams::airspeed_mps.

#include <cstdint>
#include <string>
#include <vector>

#include "core/params.h"
#include "nodes/sim/flight_estimator.h"
#include "nodes/sim/sensors.h"
#include "nodes/sim/vehicles.h"
#include "terrain/world_factory.h"

namespace nadir::sim {

struct VehicleParams {
  // "fixed_wing", "multirotor" or "rover".
  std::string kind = "fixed_wing";
  // "route": the vehicle follows route.waypoints on its own guidance;
  // "external" (rover only): it obeys drive_command_t on command_channel, each
  // from its utime on, and brakes to a stop when the newest is older than
  // command_timeout_s (a receiver's failsafe).
  std::string control = "route";
  std::string command_channel = "DRIVE_COMMAND";
  double command_timeout_s = 0.25;
  // Mission altitude: height above the ground at the start point, m (as an
  // autopilot's altitude relative to home); the height of waypoints that give none.
  double altitude_agl_m = 100.0;
  // The fixed-wing's parameters sit directly under vehicle (vehicle.airspeed_mps).
  FixedWingParams fixed_wing;
  MultirotorParams multirotor;
  RoverParams rover;

  void visit(core::ParamVisitor& v);
};

struct StartParams {
  // Start position in the world frame, m, and height above the ground there.
  double north_m = 0.0;
  double east_m = 0.0;
  double height_agl_m = 30.0;
  // Start at vehicle.altitude_agl_m instead of height_agl_m (no climb).
  bool at_mission_altitude = false;
  // Initial heading, deg from north towards east; with face_first_waypoint
  // the heading towards the first waypoint instead.
  double heading_deg = 0.0;
  bool face_first_waypoint = true;

  void visit(core::ParamVisitor& v);
};

struct RouteParams {
  // How waypoints are given: "start" ([north_m, east_m] from the start
  // position), "ned" ([north_m, east_m] in the world frame) or "geodetic"
  // ([lat_deg, lon_deg]); an optional third value is the height in m, above
  // the start's ground (or with follow_terrain, the waypoint's ground).
  std::string frame = "start";
  core::NumberRows waypoints = {};
  // Speed on the leg to each waypoint, m/s; 0 (or an empty list) keeps the
  // vehicle's cruise speed.
  std::vector<double> leg_speeds_mps = {};
  // Fly the waypoint list this many times.
  int repeat = 1;
  // Heights above the ground below each waypoint instead of the start's.
  bool follow_terrain = false;

  void visit(core::ParamVisitor& v);
};

// A recorded flight replayed as the truth instead of a simulated vehicle.
struct FlightParams {
  // Empty: the vehicle flies the route. Else a TUM file, a flight CSV or an LCM log.
  std::string path;
  // "auto" (from the extension: .tum/.txt, .csv, else LCM log), "tum", "csv" or "lcm".
  std::string format = "auto";
  // LCM logs: pose_t in the world frame on pose_channel, else
  // geodetic_position_t + attitude_t on the position and attitude channels.
  std::string pose_channel = "POSE_TRUTH";
  std::string position_channel = "NAV_POSITION";
  std::string attitude_channel = "NAV_ATTITUDE";

  void visit(core::ParamVisitor& v);
};

struct TruthParams {
  // Simulation step and truth pose_t rate, Hz.
  double rate_hz = 400.0;
  std::string channel = "POSE_TRUTH";
  // The truth split as flight stacks publish it (geodetic position with
  // relative altitude, NED attitude, NED velocity, body rates in deg/s); 0 Hz = off.
  double nav_rate_hz = 50.0;
  std::string nav_position_channel = "NAV_POSITION";
  std::string nav_attitude_channel = "NAV_ATTITUDE";
  std::string nav_velocity_channel = "NAV_VELOCITY";
  std::string nav_rates_channel = "NAV_RATES";

  void visit(core::ParamVisitor& v);
};

// A sensor model's parameters with whether it runs and where it publishes.
template <class P>
struct SensorSpec {
  bool enabled = true;
  std::string channel;
  P model;

  void visit(core::ParamVisitor& v) {
    v.field("enabled", &enabled, {.doc = "simulate and publish this sensor"});
    v.field("channel", &channel, {.doc = "channel of its messages"});
    model.visit(v);
  }
};

struct SensorsParams {
  SensorSpec<ImuParams> imu{.enabled = true, .channel = "IMU", .model = {}};
  SensorSpec<RangefinderParams> rangefinder{.enabled = true, .channel = "RANGE", .model = {}};
  SensorSpec<GpsParams> gps{.enabled = true, .channel = "GPS", .model = {}};
  SensorSpec<BarometerParams> barometer{.enabled = true, .channel = "BARO", .model = {}};
  SensorSpec<MagnetometerParams> magnetometer{.enabled = true, .channel = "MAG", .model = {}};
  // What publishes NAV_*: a flight controller's filters on these sensors, or the truth.
  AhrsParams ahrs;

  void visit(core::ParamVisitor& v);
};

// What the vehicle's guidance flies on: the truth, or a navigation source from
// the GPS denial on (sensors.gps.denied_after_s; without a denial, from the
// start). A scenario sets it as nav.source (docs/closed_loop.md).
struct GuidanceParams {
  // truth, gps (the GPS fixes, all along), nav (the navigation filter's
  // POSE_NAV), vo_feature, vo_direct or ppa (their poses).
  std::string source = "truth";
  // The estimate's channel; empty: the source's (GPS, POSE_NAV,
  // POSE_VO_FEATURE, POSE_VO_DIRECT, POSE_PPA).
  std::string channel;
  // waypoint_reached_t out: each waypoint the guidance takes as reached.
  std::string waypoint_channel = "WAYPOINT";

  void visit(core::ParamVisitor& v);
  // The channel the estimate comes on.
  std::string estimateChannel() const;
};

struct SimParams {
  // Stop after this much sim time, s; 0: when the route (or the flight) ends.
  double duration_s = 0.0;
  VehicleParams vehicle;
  StartParams start;
  RouteParams route;
  FlightParams flight;
  TruthParams truth;
  SensorsParams sensors;
  // Not a scenario key of its own: a scenario's nav.source sets it.
  GuidanceParams guidance;

  // Visits the fields at the top level of a scenario (all but guidance).
  void visit(core::ParamVisitor& v);
};

// How sim time runs when nadir-sim flies live (a batch run is as fast as it can).
// The date of a scenario that gives none: a long summer day in the north.
inline constexpr const char* kDefaultStartDate = "2024-06-21";

struct TimeParams {
  // "realtime" paces the streams at speed x real time; "batch" runs as fast as possible.
  std::string mode = "realtime";
  double speed = 1.0;
  // The run's first instant in UTC ("2024-06-21T10:00:00Z"): what a run's LCM
  // log's event times count from and, over the procedural world, where the
  // sun stands. Empty: kDefaultStartDate at 10:00 local solar time at the
  // origin (loadScenario writes it out).
  std::string start_utc;

  void visit(core::ParamVisitor& v);
};

// time.start_utc as microseconds since 1970 (kDefaultStartDate at 10:00 UTC
// when empty, for parameters made in code). Throws core::ParamError for text
// that is not a UTC date and time.
std::int64_t runStartUtime(const TimeParams& time);

// What to add to a run's message times to get its log's event times: the
// start, when the first message's time counts from 0 (a simulated run); 0
// when it is already a date (after 2000-01-01: a replayed real flight).
std::int64_t logEventOffset_us(std::int64_t start_utime, std::int64_t first_message_utime);

// What the nadir-sim process reads: the simulator's keys at the top level, as in
// a scenario, with the world it flies over and how time runs.
struct SimNodeParams {
  SimParams sim;
  terrain::WorldParams world;
  TimeParams time;
  // sim.guidance, as the nadir-sim process reads it (group "guidance").

  void visit(core::ParamVisitor& v);
};

}  // namespace nadir::sim
