#include "nodes/sim/vehicles.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>

#include "core/frames.h"

namespace nadir::sim {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
// Turns sharper than this (160 deg) are anticipated as if they were this sharp.
constexpr double kMaxAnticipatedTurn_rad = 2.8;

Eigen::Vector2d horizontal(const Eigen::Vector3d& p) { return {p.x(), p.y()}; }

// Body rates from Euler angle rates (Z-Y-X), body frame.
Eigen::Vector3d bodyRates(const core::RollPitchYaw& rpy, double roll_dot, double pitch_dot,
                          double yaw_dot) {
  const double sr = std::sin(rpy.roll_rad), cr = std::cos(rpy.roll_rad);
  const double sp = std::sin(rpy.pitch_rad), cp = std::cos(rpy.pitch_rad);
  return {roll_dot - yaw_dot * sp, pitch_dot * cr + yaw_dot * sr * cp,
          -pitch_dot * sr + yaw_dot * cr * cp};
}

// One decimal, for messages.
std::string decimal(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f", value);
  return text;
}

std::int64_t stepMicroseconds(double step_s) { return std::llround(step_s * 1e6); }

// step_s is set by the simulator, not visited with the other parameters.
void checkStep(double step_s) {
  if (!(step_s >= 1e-5 && step_s <= 0.1)) {
    throw core::ParamError("vehicle: integration step " + std::to_string(step_s) +
                           " s is out of range [1e-05, 0.1]");
  }
}

double speedOf(const std::vector<Waypoint>& waypoints, std::size_t i, double cruise_mps) {
  const std::size_t last = waypoints.size() - 1;
  const double speed = waypoints[std::min(i, last)].speed_mps;
  return speed > 0.0 ? speed : cruise_mps;
}

void checkWaypointSpeeds(const std::vector<Waypoint>& waypoints) {
  for (std::size_t i = 0; i < waypoints.size(); ++i) {
    if (!(waypoints[i].speed_mps >= 0.0) || !std::isfinite(waypoints[i].speed_mps) ||
        !waypoints[i].p_ned_m.allFinite()) {
      throw std::invalid_argument("waypoint " + std::to_string(i + 1) +
                                  " has a non-finite position or a negative speed");
    }
  }
}

}  // namespace

std::vector<Waypoint> waypointsAt(const std::vector<Eigen::Vector3d>& points_ned_m) {
  std::vector<Waypoint> waypoints;
  for (const Eigen::Vector3d& p : points_ned_m) waypoints.push_back({p, 0.0});
  return waypoints;
}

void FixedWingParams::visit(core::ParamVisitor& v) {
  v.field("airspeed_mps", &airspeed_mps, {.doc = "true airspeed, m/s", .min = 1, .max = 300});
  v.field("max_roll_rate_dps", &max_roll_rate_dps,
          {.doc = "largest roll rate, deg/s", .min = 1, .max = 720});
  v.field("max_bank_deg", &max_bank_deg, {.doc = "largest bank angle, deg", .min = 1, .max = 80});
  v.field("max_climb_rate_mps", &max_climb_rate_mps,
          {.doc = "largest climb or descent rate, m/s", .min = 0.1, .max = 50});
  v.field("lookahead_m", &lookahead_m,
          {.doc = "lateral guidance: aim this far ahead along the leg, m", .min = 1, .max = 10000});
  v.field("wind_ned_mps", &wind_ned_mps,
          {.doc = "constant wind (air moving towards) north, east, down, m/s",
           .min = -100,
           .max = 100,
           .list_size = 3});
  v.field("turbulence_mps", &turbulence_mps,
          {.doc = "standard deviation of the gusts per axis, m/s; 0 = calm", .min = 0, .max = 30});
  v.field("turbulence_time_constant_s", &turbulence_time_constant_s,
          {.doc = "correlation time of the gusts, s", .min = 0.01, .max = 600});
  v.field("seed", &seed, {.doc = "seed of the turbulence"});
  v.field(
      "max_acceleration_mps2", &max_acceleration_mps2,
      {.doc = "airspeed change between legs of different speeds, m/s^2", .min = 0.01, .max = 50});
}

FixedWing::FixedWing(const FixedWingParams& params, const Eigen::Vector3d& start_ned,
                     double heading_rad, std::vector<Waypoint> waypoints)
    : params_(params),
      waypoints_(std::move(waypoints)),
      leg_start_ned_(start_ned),
      heading_rad_(heading_rad),
      noise_(static_cast<std::uint64_t>(params.seed)) {
  core::validateParams([this](core::ParamVisitor& v) { params_.visit(v); }, "vehicle");
  checkStep(params_.step_s);
  if (waypoints_.empty()) throw std::invalid_argument("the fixed-wing has no waypoint to fly to");
  checkWaypointSpeeds(waypoints_);
  // Each turn starts a lead distance r tan(turn / 2) before its waypoint (see
  // step()); a leg too short for the leads of the turns at both its ends
  // cannot be flown through.
  const auto turnAt = [this, &start_ned](std::size_t i) {
    if (i + 1 >= waypoints_.size()) return 0.0;
    const Eigen::Vector3d& from = i == 0 ? start_ned : waypoints_[i - 1].p_ned_m;
    const Eigen::Vector2d in = horizontal(waypoints_[i].p_ned_m) - horizontal(from);
    const Eigen::Vector2d out =
        horizontal(waypoints_[i + 1].p_ned_m) - horizontal(waypoints_[i].p_ned_m);
    return std::abs(core::wrapAngle_rad(std::atan2(out.y(), out.x()) - std::atan2(in.y(), in.x())));
  };
  for (std::size_t i = 0; i < waypoints_.size(); ++i) {
    const Eigen::Vector3d& from = i == 0 ? start_ned : waypoints_[i - 1].p_ned_m;
    const double leg_m = (horizontal(waypoints_[i].p_ned_m) - horizontal(from)).norm();
    const double speed_mps = std::max(legSpeed_mps(i), legSpeed_mps(i + 1));
    const double radius_m = turnRadius_m(speed_mps);
    const double lead_in_m =
        i == 0 ? 0.0 : radius_m * std::tan(0.5 * std::min(turnAt(i - 1), kMaxAnticipatedTurn_rad));
    const double lead_out_m =
        radius_m * std::tan(0.5 * std::min(turnAt(i), kMaxAnticipatedTurn_rad));
    if (leg_m < lead_in_m + lead_out_m) {
      throw std::invalid_argument("waypoint " + std::to_string(i + 1) + " is " + decimal(leg_m) +
                                  " m from the one before: the turns at the ends of that leg "
                                  "need " +
                                  decimal(lead_in_m + lead_out_m) + " m at " + decimal(speed_mps) +
                                  " m/s and " + decimal(params_.max_bank_deg) + " deg bank");
    }
  }
  airspeed_mps_ = legSpeed_mps(0);
  state_.p_ned_m = start_ned;
  state_.v_ned_mps =
      airspeed_mps_ * Eigen::Vector3d(std::cos(heading_rad), std::sin(heading_rad), 0.0) +
      Eigen::Vector3d(params_.wind_ned_mps[0], params_.wind_ned_mps[1], params_.wind_ned_mps[2]);
  state_.q_world_body = core::quaternionFromRpy({0.0, 0.0, heading_rad});
}

double FixedWing::turnRadius_m(double airspeed_mps) const {
  return airspeed_mps * airspeed_mps / (kGravity_mps2 * std::tan(params_.max_bank_deg * kDeg));
}

double FixedWing::legSpeed_mps(std::size_t waypoint) const {
  return speedOf(waypoints_, waypoint, params_.airspeed_mps);
}

void FixedWing::step() {
  const double dt = params_.step_s;
  const double max_speed_step = params_.max_acceleration_mps2 * dt;
  airspeed_mps_ +=
      std::clamp(legSpeed_mps(next_waypoint_) - airspeed_mps_, -max_speed_step, max_speed_step);
  const double airspeed = airspeed_mps_;
  const double max_bank = params_.max_bank_deg * kDeg;
  // The guidance flies on where it believes the aircraft is.
  const Eigen::Vector3d p = state_.p_ned_m + position_error_m_;

  // Waypoint switching, with turn anticipation: start the turn where an arc at
  // the maximum bank joins the next leg.
  double bank_command = 0.0;
  double altitude_target_m = -p.z();
  if (!finished()) {
    const Eigen::Vector3d& target = waypoints_[next_waypoint_].p_ned_m;
    const Eigen::Vector2d leg = horizontal(target) - horizontal(leg_start_ned_);
    const Eigen::Vector2d leg_unit = leg.normalized();
    const double along_m = (horizontal(p) - horizontal(leg_start_ned_)).dot(leg_unit);
    double lead_m = 0.0;
    if (next_waypoint_ + 1 < waypoints_.size()) {
      const Eigen::Vector2d next_leg =
          horizontal(waypoints_[next_waypoint_ + 1].p_ned_m) - horizontal(target);
      const double turn_rad = std::abs(core::wrapAngle_rad(std::atan2(next_leg.y(), next_leg.x()) -
                                                           std::atan2(leg.y(), leg.x())));
      lead_m = std::min(
          turnRadius_m(airspeed) * std::tan(0.5 * std::min(turn_rad, kMaxAnticipatedTurn_rad)),
          0.5 * leg.norm());
    }
    if (along_m >= leg.norm() - lead_m) {
      leg_start_ned_ = target;
      ++next_waypoint_;
    }
  }
  if (!finished()) {
    const Eigen::Vector3d& target = waypoints_[next_waypoint_].p_ned_m;
    altitude_target_m = -target.z();
    const Eigen::Vector2d leg_unit = (horizontal(target) - horizontal(leg_start_ned_)).normalized();
    const Eigen::Vector2d from_start = horizontal(p) - horizontal(leg_start_ned_);
    const Eigen::Vector2d carrot =
        horizontal(leg_start_ned_) + (from_start.dot(leg_unit) + params_.lookahead_m) * leg_unit;
    const Eigen::Vector2d to_carrot = carrot - horizontal(p);
    const double course_rad = std::atan2(state_.v_ned_mps.y(), state_.v_ned_mps.x());
    const double error_rad =
        core::wrapAngle_rad(std::atan2(to_carrot.y(), to_carrot.x()) - course_rad);
    // Turn rate that closes the course error over the lookahead distance; past
    // 90 deg off course, the full rate towards it.
    const double limited_error = std::clamp(error_rad, -std::numbers::pi / 2, std::numbers::pi / 2);
    const double turn_rate_rps = 2.0 * airspeed * std::sin(limited_error) / params_.lookahead_m;
    bank_command =
        std::clamp(std::atan(airspeed * turn_rate_rps / kGravity_mps2), -max_bank, max_bank);
  }
  const double max_roll_step = params_.max_roll_rate_dps * kDeg * dt;
  const double previous_bank = bank_rad_;
  bank_rad_ += std::clamp(bank_command - bank_rad_, -max_roll_step, max_roll_step);

  const double yaw_rate_rps = kGravity_mps2 * std::tan(bank_rad_) / airspeed;
  heading_rad_ = core::wrapAngle_rad(heading_rad_ + yaw_rate_rps * dt);

  const double climb_command = std::clamp(0.5 * (altitude_target_m - (-p.z())),
                                          -params_.max_climb_rate_mps, params_.max_climb_rate_mps);
  constexpr double kMaxClimbAcceleration_mps2 = 2.0;
  const double previous_gamma = std::asin(climb_rate_mps_ / airspeed);
  climb_rate_mps_ += std::clamp(climb_command - climb_rate_mps_, -kMaxClimbAcceleration_mps2 * dt,
                                kMaxClimbAcceleration_mps2 * dt);
  const double gamma = std::asin(std::clamp(climb_rate_mps_ / airspeed, -1.0, 1.0));

  if (params_.turbulence_mps > 0.0) {
    const double tau = params_.turbulence_time_constant_s;
    for (int i = 0; i < 3; ++i) {
      gust_ned_mps_[i] += -gust_ned_mps_[i] / tau * dt + params_.turbulence_mps *
                                                             std::sqrt(2.0 * dt / tau) *
                                                             noise_.standardNormal();
    }
  }
  const Eigen::Vector3d air_velocity =
      airspeed * Eigen::Vector3d(std::cos(heading_rad_) * std::cos(gamma),
                                 std::sin(heading_rad_) * std::cos(gamma), -std::sin(gamma));
  const Eigen::Vector3d wind(params_.wind_ned_mps[0], params_.wind_ned_mps[1],
                             params_.wind_ned_mps[2]);
  const Eigen::Vector3d velocity = air_velocity + wind + gust_ned_mps_;
  state_.a_ned_mps2 = (velocity - state_.v_ned_mps) / dt;
  state_.v_ned_mps = velocity;
  state_.p_ned_m += velocity * dt;
  const core::RollPitchYaw rpy{bank_rad_, gamma, heading_rad_};
  state_.q_world_body = core::quaternionFromRpy(rpy);
  state_.omega_body_rps =
      bodyRates(rpy, (bank_rad_ - previous_bank) / dt, (gamma - previous_gamma) / dt, yaw_rate_rps);
  state_.utime += stepMicroseconds(dt);
}

void MultirotorParams::visit(core::ParamVisitor& v) {
  v.field("speed_mps", &speed_mps, {.doc = "cruise speed along a leg, m/s", .min = 0.1, .max = 50});
  v.field("acceleration_mps2", &acceleration_mps2,
          {.doc = "acceleration and braking, m/s^2", .min = 0.1, .max = 20});
  v.field("yaw_rate_dps", &yaw_rate_dps,
          {.doc = "yaw rate when turning, deg/s", .min = 1, .max = 720});
  v.field("max_tilt_rate_dps", &max_tilt_rate_dps,
          {.doc = "fastest roll or pitch change of the attitude controller, deg/s",
           .min = 1,
           .max = 2000});
  v.field("yaw_at_corners", &yaw_at_corners,
          {.doc = "stop and turn to face each new leg (else keep the start heading)"});
  v.field("acceptance_radius_m", &acceptance_radius_m,
          {.doc = "guided on an estimate: a waypoint is reached this close horizontally, m",
           .min = 0.01,
           .max = 1000});
  v.field("altitude_acceptance_m", &altitude_acceptance_m,
          {.doc = "guided on an estimate: and this close in height, m", .min = 0.01, .max = 1000});
}

Multirotor::Multirotor(const MultirotorParams& params, const Eigen::Vector3d& start_ned,
                       double heading_rad, std::vector<Waypoint> waypoints)
    : params_(params), waypoints_(std::move(waypoints)), yaw_rad_(heading_rad) {
  core::validateParams([this](core::ParamVisitor& v) { params_.visit(v); }, "vehicle");
  checkStep(params_.step_s);
  if (waypoints_.empty()) throw std::invalid_argument("the multirotor has no waypoint to fly to");
  checkWaypointSpeeds(waypoints_);
  state_.p_ned_m = start_ned;
  state_.q_world_body = core::quaternionFromRpy({0.0, 0.0, heading_rad});
}

void Multirotor::step() {
  const double dt = params_.step_s;
  const Eigen::Vector3d previous_velocity = state_.v_ned_mps;
  const core::RollPitchYaw previous_rpy = core::rpyFromQuaternion(state_.q_world_body);
  double yaw_rate_rps = 0.0;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  if (!finished()) {
    const Eigen::Vector3d to_target =
        waypoints_[next_waypoint_].p_ned_m - (state_.p_ned_m + position_error_m_);
    const double distance_m = to_target.norm();
    const double leg_course = std::atan2(to_target.y(), to_target.x());
    const double yaw_error = core::wrapAngle_rad(leg_course - yaw_rad_);
    const double max_yaw_step = params_.yaw_rate_dps * kDeg * dt;
    const bool must_turn = params_.yaw_at_corners && speed_mps_ == 0.0 &&
                           horizontal(to_target).norm() > 1e-6 && std::abs(yaw_error) > 1e-9;
    if (must_turn) {
      const double yaw_step = std::clamp(yaw_error, -max_yaw_step, max_yaw_step);
      yaw_rad_ = core::wrapAngle_rad(yaw_rad_ + yaw_step);
      yaw_rate_rps = yaw_step / dt;
    } else if (stopping_) {
      speed_mps_ = std::max(0.0, speed_mps_ - params_.acceleration_mps2 * dt);
      velocity = stop_direction_ * speed_mps_;
      if (speed_mps_ == 0.0) {
        stopping_ = false;
        ++next_waypoint_;
      }
    } else {
      // Accelerate to cruise, brake so as to stop on the waypoint.
      speed_mps_ = std::min({speed_mps_ + params_.acceleration_mps2 * dt,
                             speedOf(waypoints_, next_waypoint_, params_.speed_mps),
                             std::sqrt(2.0 * params_.acceleration_mps2 * distance_m)});
      const bool accepted = on_estimate_ &&
                            horizontal(to_target).norm() <= params_.acceptance_radius_m &&
                            std::abs(to_target.z()) <= params_.altitude_acceptance_m;
      if (distance_m <= speed_mps_ * dt || distance_m < 1e-9) {
        velocity = to_target / dt;
        speed_mps_ = 0.0;
        ++next_waypoint_;
      } else if (accepted) {
        stopping_ = true;
        stop_direction_ = to_target / distance_m;
        velocity = stop_direction_ * speed_mps_;
      } else {
        velocity = to_target / distance_m * speed_mps_;
      }
    }
  }
  state_.p_ned_m += velocity * dt;
  // On arrival the position snaps onto the waypoint and the vehicle is at rest.
  state_.v_ned_mps = speed_mps_ == 0.0 ? Eigen::Vector3d::Zero() : velocity;
  state_.a_ned_mps2 = (state_.v_ned_mps - previous_velocity) / dt;
  // Stopping on a waypoint drops the last few mm/s within one step; the
  // vehicle brakes at its acceleration limit, so the step's mean acceleration
  // (and the tilt it causes) is capped there rather than spiking.
  const double a_norm = state_.a_ned_mps2.norm();
  if (a_norm > params_.acceleration_mps2) state_.a_ned_mps2 *= params_.acceleration_mps2 / a_norm;
  // Tilt: the thrust must supply the horizontal acceleration, seen in the heading frame.
  const Eigen::Vector3d& a = state_.a_ned_mps2;
  const double forward = std::cos(yaw_rad_) * a.x() + std::sin(yaw_rad_) * a.y();
  const double right = -std::sin(yaw_rad_) * a.x() + std::cos(yaw_rad_) * a.y();
  const double pitch_command = -std::atan2(forward, kGravity_mps2 - a.z());
  const double roll_command = std::atan2(right * std::cos(pitch_command), kGravity_mps2 - a.z());
  const double max_tilt_step = params_.max_tilt_rate_dps * kDeg * dt;
  pitch_rad_ += std::clamp(pitch_command - pitch_rad_, -max_tilt_step, max_tilt_step);
  roll_rad_ += std::clamp(roll_command - roll_rad_, -max_tilt_step, max_tilt_step);
  const double pitch = pitch_rad_, roll = roll_rad_;
  const core::RollPitchYaw rpy{roll, pitch, yaw_rad_};
  state_.q_world_body = core::quaternionFromRpy(rpy);
  state_.omega_body_rps = bodyRates(rpy, (roll - previous_rpy.roll_rad) / dt,
                                    (pitch - previous_rpy.pitch_rad) / dt, yaw_rate_rps);
  state_.utime += stepMicroseconds(dt);
}

void RoverParams::visit(core::ParamVisitor& v) {
  v.field("speed_mps", &speed_mps, {.doc = "driving speed, m/s", .min = 0.01, .max = 50});
  v.field("wheelbase_m", &wheelbase_m, {.doc = "front to rear axle, m", .min = 0.01, .max = 10});
  v.field("max_steer_deg", &max_steer_deg,
          {.doc = "largest steering angle, deg", .min = 1, .max = 60});
  v.field("max_steer_rate_dps", &max_steer_rate_dps,
          {.doc = "largest steering rate, deg/s", .min = 1, .max = 1000});
  v.field("lookahead_m", &lookahead_m,
          {.doc = "pure pursuit lookahead, m", .min = 0.01, .max = 100});
  v.field("arrival_radius_m", &arrival_radius_m,
          {.doc = "a waypoint is reached within this distance, m", .min = 0.001, .max = 100});
  v.field("max_acceleration_mps2", &max_acceleration_mps2,
          {.doc = "external control: speeding up, m/s^2", .min = 0.01, .max = 100});
  v.field("max_deceleration_mps2", &max_deceleration_mps2,
          {.doc = "external control: braking, m/s^2", .min = 0.01, .max = 100});
  v.field("max_lateral_acceleration_mps2", &max_lateral_acceleration_mps2,
          {.doc = "the tyres' grip: curvature held to this over speed squared; 0: no limit",
           .min = 0,
           .max = 1000});
  v.field("length_m", &length_m,
          {.doc = "body length (for collisions), m", .min = 0.01, .max = 20});
  v.field("width_m", &width_m, {.doc = "body width (for collisions), m", .min = 0.01, .max = 10});
  v.field("rear_overhang_m", &rear_overhang_m,
          {.doc = "body's back behind the rear axle, m", .min = 0, .max = 10});
}

Rover::Rover(const RoverParams& params, const Eigen::Vector3d& start_ned, double heading_rad)
    : params_(params), external_(true), heading_rad_(heading_rad) {
  core::validateParams([this](core::ParamVisitor& v) { params_.visit(v); }, "vehicle");
  checkStep(params_.step_s);
  state_.p_ned_m = start_ned;
  state_.q_world_body = core::quaternionFromRpy({0.0, 0.0, heading_rad});
}

void Rover::command(double steer_rad, double speed_mps) {
  steer_command_rad_ = steer_rad;
  speed_command_mps_ = std::max(0.0, speed_mps);
}

Rover::Rover(const RoverParams& params, const Eigen::Vector3d& start_ned, double heading_rad,
             std::vector<Waypoint> waypoints)
    : params_(params), waypoints_(std::move(waypoints)), heading_rad_(heading_rad) {
  core::validateParams([this](core::ParamVisitor& v) { params_.visit(v); }, "vehicle");
  checkStep(params_.step_s);
  if (waypoints_.empty()) throw std::invalid_argument("the rover has no waypoint to drive to");
  checkWaypointSpeeds(waypoints_);
  state_.p_ned_m = start_ned;
  state_.q_world_body = core::quaternionFromRpy({0.0, 0.0, heading_rad});
}

void Rover::step() {
  const double dt = params_.step_s;
  const Eigen::Vector3d previous_velocity = state_.v_ned_mps;
  double speed = 0.0;
  double steer_command = 0.0;
  if (external_) {
    steer_command = steer_command_rad_;
    const double change = speed_command_mps_ - speed_mps_;
    speed_mps_ +=
        std::clamp(change, -params_.max_deceleration_mps2 * dt, params_.max_acceleration_mps2 * dt);
    speed = speed_mps_;
  } else if (!finished() && (horizontal(waypoints_[next_waypoint_].p_ned_m) -
                             horizontal(state_.p_ned_m + position_error_m_))
                                    .norm() <= params_.arrival_radius_m) {
    ++next_waypoint_;
  }
  if (!external_ && !finished()) {
    speed = speedOf(waypoints_, next_waypoint_, params_.speed_mps);
    // Pure pursuit: the arc through the goal point ahead, curvature 2 sin(alpha) / L.
    const Eigen::Vector2d to_goal = horizontal(waypoints_[next_waypoint_].p_ned_m) -
                                    horizontal(state_.p_ned_m + position_error_m_);
    const double alpha = core::wrapAngle_rad(std::atan2(to_goal.y(), to_goal.x()) - heading_rad_);
    const double distance = std::max(std::min(to_goal.norm(), params_.lookahead_m), 1e-6);
    // A goal behind gets the tightest turn towards it, not none.
    const double curvature =
        2.0 * std::sin(std::clamp(alpha, -std::numbers::pi / 2, std::numbers::pi / 2)) / distance;
    steer_command = std::atan(params_.wheelbase_m * curvature);
  }
  const double max_steer = params_.max_steer_deg * kDeg;
  const double max_steer_step = params_.max_steer_rate_dps * kDeg * dt;
  steer_rad_ += std::clamp(std::clamp(steer_command, -max_steer, max_steer) - steer_rad_,
                           -max_steer_step, max_steer_step);
  speed_mps_ = speed;
  double curvature = std::tan(steer_rad_) / params_.wheelbase_m;
  if (params_.max_lateral_acceleration_mps2 > 0.0 && speed > 0.0) {
    const double grip = params_.max_lateral_acceleration_mps2 / (speed * speed);
    curvature = std::clamp(curvature, -grip, grip);
  }
  const double yaw_rate_rps = speed * curvature;
  heading_rad_ = core::wrapAngle_rad(heading_rad_ + yaw_rate_rps * dt);
  state_.v_ned_mps = speed * Eigen::Vector3d(std::cos(heading_rad_), std::sin(heading_rad_), 0.0);
  state_.p_ned_m += state_.v_ned_mps * dt;
  state_.a_ned_mps2 = (state_.v_ned_mps - previous_velocity) / dt;
  state_.q_world_body = core::quaternionFromRpy({0.0, 0.0, heading_rad_});
  state_.omega_body_rps = Eigen::Vector3d(0.0, 0.0, yaw_rate_rps);
  state_.utime += stepMicroseconds(dt);
}

}  // namespace nadir::sim
