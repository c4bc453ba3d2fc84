#pragma once
// The simulator: a vehicle flying its route (or a recorded flight replayed)
// stepped at the truth rate in sim time, with its sensors sampled on their
// own fixed grids. Plain structs out; the node or the batch runner turns them
// into messages. Deterministic: the same params and seeds give the same outputs.

#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "core/geodesy.h"
#include "nodes/sim/flight_estimator.h"
#include "nodes/sim/flight_replay.h"
#include "nodes/sim/nav_truth.h"
#include "nodes/sim/sensors.h"
#include "nodes/sim/sim_params.h"
#include "nodes/sim/vehicles.h"
#include "terrain/world.h"

namespace nadir::sim {

// The route in the world frame: start, initial heading, waypoints with
// repeat applied and heights resolved against the terrain.
struct ResolvedRoute {
  Eigen::Vector3d start_ned_m = Eigen::Vector3d::Zero();
  double start_heading_rad = 0.0;
  std::vector<Waypoint> waypoints;
};

// Throws core::ParamError naming the key for an empty route or a speed list
// whose length does not match the waypoints.
ResolvedRoute resolveRoute(const SimParams& params, const terrain::World& world,
                           const core::LocalNedFrame& frame);

// A steering and speed command for a rover under external control, in effect
// from utime on.
struct DriveInput {
  std::int64_t utime = 0;
  double steer_rad = 0.0;
  double speed_mps = 0.0;
};

// The guidance took a waypoint as reached (world frame, m): what the
// simulator publishes as waypoint_reached_t, as its sensors' samples are.
using WaypointEvent = msg::WaypointReached;

// One simulation step: the true state and the sensor samples that fell due.
struct SimOutput {
  VehicleState truth;
  std::optional<ImuSample> imu;
  std::optional<RangeSample> range;
  std::optional<GpsSample> gps;
  std::optional<BaroSample> baro;
  std::optional<MagSample> mag;
  // The NAV_* messages, when due (at truth.nav_rate_hz): the flight
  // controller's estimate (sensors.ahrs), or the truth with ideal.
  std::optional<NavMessages> nav;
  // A waypoint the guidance took as reached in this step.
  std::optional<WaypointEvent> waypoint;
};

class Simulator {
 public:
  // With a flight, it is the truth from its first to its last pose (the vehicle
  // and route are not used); else the vehicle of params.vehicle.kind flies the
  // route. Throws core::ParamError for parameters that cannot be flown (an
  // unreachable waypoint among them) or an estimator without its sensors,
  // naming the key.
  Simulator(const SimParams& params, std::shared_ptr<const terrain::World> world,
            const core::LocalNedFrame& frame, std::optional<FlightReplay> flight = std::nullopt);

  // The first call gives the initial state; each later call advances one step
  // of 1 / truth.rate_hz.
  SimOutput step();
  // True once the route or the flight has ended or duration_s has passed; under
  // external control, also once the rover has stood still for a second after
  // moving.
  bool finished() const;
  // External control: a command, in effect from its utime (commands are kept
  // in time order; a command for a time already past takes effect at the
  // next step). Throws std::logic_error without external control.
  void drive(const DriveInput& command);
  bool externalControl() const { return external_; }

  // A navigation source's position at utime (guidance.source other than
  // truth): from the GPS denial on (gps: all along) the guidance flies on it,
  // its error against the truth at its time held until the next. A fix older
  // than the truth kept (5 s) or newer than now is ignored.
  void positionFix(std::int64_t utime, const Eigen::Vector3d& p_ned_m);
  // What the guidance flies on now: the truth until the source's first fix
  // (a source that never gives one is never flown on, nor reported as such).
  std::string guidanceSource() const;

  std::int64_t startUtime() const { return start_utime_; }
  // Ellipsoid altitude of the start, m: the zero of the NAV relative altitude.
  double startAltitude_m() const { return start_altitude_m_; }
  const ResolvedRoute& route() const { return route_; }
  const core::LocalNedFrame& frame() const { return frame_; }
  // The flight controller's filters; empty with sensors.ahrs.estimator ideal.
  const std::optional<FlightEstimator>& estimator() const { return estimator_; }

 private:
  VehicleState currentState() const;
  bool vehicleFinished() const;
  NavMessages navMessages(const VehicleState& truth) const;

  SimParams params_;
  std::shared_ptr<const terrain::World> world_;
  core::LocalNedFrame frame_;
  std::optional<FlightReplay> flight_;
  ResolvedRoute route_;
  std::variant<std::monostate, FixedWing, Multirotor, Rover> vehicle_;
  bool external_ = false;
  std::vector<DriveInput> pending_commands_;
  std::optional<DriveInput> applied_command_;
  bool rover_moved_ = false;
  // The truth's recent positions (for a fix's error at its time).
  std::deque<std::pair<std::int64_t, Eigen::Vector3d>> recent_truth_;
  Eigen::Vector3d position_error_m_ = Eigen::Vector3d::Zero();
  bool has_source_fix_ = false;
  void setPositionError(const Eigen::Vector3d& error_m);
  std::size_t vehicleNextWaypoint() const;
  bool guidanceOnSource(std::int64_t utime) const;
  std::int64_t rover_still_since_ = -1;
  void applyCommands();
  std::int64_t step_us_ = 0;
  std::int64_t start_utime_ = 0;
  std::int64_t utime_ = 0;
  bool started_ = false;
  double start_altitude_m_ = 0.0;

  std::optional<ImuModel> imu_;
  std::optional<RangefinderModel> rangefinder_;
  std::optional<GpsModel> gps_;
  std::optional<BarometerModel> barometer_;
  std::optional<MagnetometerModel> magnetometer_;
  std::optional<FlightEstimator> estimator_;
  std::int64_t imu_due_ = core::kDueAtFirstCall;
  std::int64_t range_due_ = core::kDueAtFirstCall;
  std::int64_t gps_due_ = core::kDueAtFirstCall;
  std::int64_t baro_due_ = core::kDueAtFirstCall;
  std::int64_t mag_due_ = core::kDueAtFirstCall;
  std::int64_t nav_due_ = core::kDueAtFirstCall;
};

}  // namespace nadir::sim
