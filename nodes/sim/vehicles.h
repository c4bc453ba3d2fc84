#pragma once
// Vehicle models for the simulator: kinematic, deterministic, stepped at a
// fixed rate in sim time. Each follows a list of waypoints in the world frame
// (local NED) and exposes its true state. No LCM here.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/params.h"
#include "nodes/sim/noise.h"
#include "nodes/sim/vehicle_state.h"

namespace nadir::sim {

// A point in the world frame (local NED) to go to, and the speed on the leg
// that ends there; 0 takes the vehicle's cruise speed.
struct Waypoint {
  Eigen::Vector3d p_ned_m = Eigen::Vector3d::Zero();
  double speed_mps = 0.0;
};

std::vector<Waypoint> waypointsAt(const std::vector<Eigen::Vector3d>& points_ned_m);

// Fixed-wing aircraft in coordinated flight: constant airspeed, turn rate
// g tan(bank) / airspeed, bank limited in angle and rate, climb rate limited,
// waypoints followed along their legs with turn anticipation, optional
// constant wind and seeded turbulence.
struct FixedWingParams {
  double airspeed_mps = 20.0;
  double max_roll_rate_dps = 45.0;
  double max_bank_deg = 45.0;
  double max_climb_rate_mps = 3.0;
  // Lateral guidance: aim at a point this far ahead along the current leg.
  double lookahead_m = 80.0;
  std::vector<double> wind_ned_mps = {0.0, 0.0, 0.0};
  // Turbulence: a first-order (Dryden-like) gust per axis, standard deviation.
  double turbulence_mps = 0.0;
  double turbulence_time_constant_s = 2.0;
  std::int64_t seed = 1;
  // Rate of an airspeed change between legs of different speeds, m/s^2.
  double max_acceleration_mps2 = 1.0;
  // Integration step, s; set by the simulator (not a scenario key).
  double step_s = 0.0025;

  void visit(core::ParamVisitor& v);
};

class FixedWing {
 public:
  // Starts at start_ned, flying level along heading_rad, towards the waypoints.
  // Throws std::invalid_argument for an empty waypoint list or a waypoint the
  // aircraft cannot fly through: a leg shorter than the turns at its two ends
  // need (r tan(turn / 2) each, r the turn radius at the maximum bank and the
  // faster of the adjoining legs' speeds).
  FixedWing(const FixedWingParams& params, const Eigen::Vector3d& start_ned, double heading_rad,
            std::vector<Waypoint> waypoints);
  FixedWing(const FixedWingParams& params, const Eigen::Vector3d& start_ned, double heading_rad,
            const std::vector<Eigen::Vector3d>& waypoints_ned)
      : FixedWing(params, start_ned, heading_rad, waypointsAt(waypoints_ned)) {}

  // Advances one step of params.step_s.
  void step();
  const VehicleState& state() const { return state_; }
  // Where the guidance believes the vehicle is, less where it is: the guidance
  // flies on the true position plus this (a navigation source's error).
  void setPositionError(const Eigen::Vector3d& believed_minus_true_m) {
    position_error_m_ = believed_minus_true_m;
  }
  const Eigen::Vector3d& positionError() const { return position_error_m_; }
  const std::vector<Waypoint>& waypoints() const { return waypoints_; }
  // True once the last waypoint has been passed.
  bool finished() const { return next_waypoint_ >= waypoints_.size(); }
  double bank_rad() const { return bank_rad_; }
  double heading_rad() const { return heading_rad_; }
  double airspeed_mps() const { return airspeed_mps_; }
  std::size_t nextWaypoint() const { return next_waypoint_; }
  // Radius of a turn at the maximum bank and params.airspeed_mps, m.
  double minimumTurnRadius_m() const { return turnRadius_m(params_.airspeed_mps); }

 private:
  double turnRadius_m(double airspeed_mps) const;
  double legSpeed_mps(std::size_t waypoint) const;

  FixedWingParams params_;
  std::vector<Waypoint> waypoints_;
  std::size_t next_waypoint_ = 0;
  Eigen::Vector3d leg_start_ned_;
  VehicleState state_;
  double heading_rad_ = 0.0;
  double bank_rad_ = 0.0;
  double airspeed_mps_ = 0.0;
  double climb_rate_mps_ = 0.0;
  Eigen::Vector3d position_error_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d gust_ned_mps_ = Eigen::Vector3d::Zero();
  GaussianNoise noise_;
};

// Multirotor: flies each leg at a set speed with limited acceleration,
// stopping at waypoints; with yaw_at_corners it turns on the spot to face each
// new leg (the 90 deg yaw at the rectangle's corners of McConville et al. (2020)). Tilt follows
// the acceleration.
struct MultirotorParams {
  double speed_mps = 3.0;
  double acceleration_mps2 = 1.5;
  double yaw_rate_dps = 45.0;
  // The attitude controller tilts the vehicle towards what the acceleration
  // needs no faster than this, deg/s (so the tilt does not jump when braking starts).
  double max_tilt_rate_dps = 60.0;
  bool yaw_at_corners = true;
  // Guided on an estimate (setPositionError), a waypoint is reached within
  // these of where the vehicle believes it is, horizontally and in height, as
  // a flight controller's acceptance radii: a noisy estimate is never exactly
  // on it. The vehicle then brakes to a stop. On the truth it stops on it.
  double acceptance_radius_m = 0.3;
  double altitude_acceptance_m = 0.5;
  // Integration step, s; set by the simulator (not a scenario key).
  double step_s = 0.0025;

  void visit(core::ParamVisitor& v);
};

class Multirotor {
 public:
  Multirotor(const MultirotorParams& params, const Eigen::Vector3d& start_ned, double heading_rad,
             std::vector<Waypoint> waypoints);
  Multirotor(const MultirotorParams& params, const Eigen::Vector3d& start_ned, double heading_rad,
             const std::vector<Eigen::Vector3d>& waypoints_ned)
      : Multirotor(params, start_ned, heading_rad, waypointsAt(waypoints_ned)) {}
  void step();
  const VehicleState& state() const { return state_; }
  // As FixedWing::setPositionError; from the first call on, waypoints are
  // reached within the acceptance radii.
  void setPositionError(const Eigen::Vector3d& believed_minus_true_m) {
    position_error_m_ = believed_minus_true_m;
    on_estimate_ = true;
  }
  const Eigen::Vector3d& positionError() const { return position_error_m_; }
  const std::vector<Waypoint>& waypoints() const { return waypoints_; }
  bool finished() const { return next_waypoint_ >= waypoints_.size(); }
  std::size_t nextWaypoint() const { return next_waypoint_; }
  double yaw_rad() const { return yaw_rad_; }

 private:
  MultirotorParams params_;
  Eigen::Vector3d position_error_m_ = Eigen::Vector3d::Zero();
  bool on_estimate_ = false;
  // Within the acceptance radii: braking to a stop along stop_direction_.
  bool stopping_ = false;
  Eigen::Vector3d stop_direction_ = Eigen::Vector3d::Zero();
  std::vector<Waypoint> waypoints_;
  std::size_t next_waypoint_ = 0;
  VehicleState state_;
  double yaw_rad_ = 0.0;
  double speed_mps_ = 0.0;
  double roll_rad_ = 0.0;
  double pitch_rad_ = 0.0;
};

// Ground rover: kinematic bicycle model (rear-axle reference point) on flat
// ground, steering limited in angle and rate, following waypoints by pure
// pursuit at a constant speed, or (external) the steering and speed it is
// commanded, reaching the speed at limited acceleration (for Liu et al.'s
// (2021) gate and slalom tasks).
struct RoverParams {
  double speed_mps = 1.0;
  double wheelbase_m = 0.3;
  double max_steer_deg = 30.0;
  double max_steer_rate_dps = 90.0;
  double lookahead_m = 1.0;
  // A waypoint counts as reached within this distance.
  double arrival_radius_m = 0.2;
  // External control: speeding up and braking, m/s^2.
  double max_acceleration_mps2 = 6.0;
  double max_deceleration_mps2 = 8.0;
  // The tyres' grip: the path's curvature is held to this lateral
  // acceleration over the speed squared (the car runs wide); 0: no limit.
  double max_lateral_acceleration_mps2 = 0.0;
  // The body's footprint (for collisions): length, width, and how far its
  // back lies behind the rear axle, m.
  double length_m = 0.43;
  double width_m = 0.18;
  double rear_overhang_m = 0.08;
  // Integration step, s; set by the simulator (not a scenario key).
  double step_s = 0.0025;

  void visit(core::ParamVisitor& v);
};

class Rover {
 public:
  Rover(const RoverParams& params, const Eigen::Vector3d& start_ned, double heading_rad,
        std::vector<Waypoint> waypoints);
  Rover(const RoverParams& params, const Eigen::Vector3d& start_ned, double heading_rad,
        const std::vector<Eigen::Vector3d>& waypoints_ned)
      : Rover(params, start_ned, heading_rad, waypointsAt(waypoints_ned)) {}
  // Under external control: standing at start_ned until commanded.
  Rover(const RoverParams& params, const Eigen::Vector3d& start_ned, double heading_rad);
  // External control: the steering angle (positive turns right) and the speed
  // to reach; both limited as the params say.
  void command(double steer_rad, double speed_mps);
  void step();
  const VehicleState& state() const { return state_; }
  // As FixedWing::setPositionError (for following waypoints).
  void setPositionError(const Eigen::Vector3d& believed_minus_true_m) {
    position_error_m_ = believed_minus_true_m;
  }
  const Eigen::Vector3d& positionError() const { return position_error_m_; }
  const std::vector<Waypoint>& waypoints() const { return waypoints_; }
  std::size_t nextWaypoint() const { return next_waypoint_; }
  // Following waypoints: the last one passed; under external control, never.
  bool finished() const { return !external_ && next_waypoint_ >= waypoints_.size(); }
  double steer_rad() const { return steer_rad_; }
  double heading_rad() const { return heading_rad_; }
  double speed_mps() const { return speed_mps_; }

 private:
  RoverParams params_;
  bool external_ = false;
  Eigen::Vector3d position_error_m_ = Eigen::Vector3d::Zero();
  double steer_command_rad_ = 0.0;
  double speed_command_mps_ = 0.0;
  double speed_mps_ = 0.0;
  std::vector<Waypoint> waypoints_;
  std::size_t next_waypoint_ = 0;
  VehicleState state_;
  double heading_rad_ = 0.0;
  double steer_rad_ = 0.0;
};

}  // namespace nadir::sim
