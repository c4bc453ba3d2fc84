#include "nodes/control/gate_controller.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace nadir::control {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

double seconds(std::int64_t us) { return static_cast<double>(us) * 1e-6; }

}  // namespace

void PidGains::visit(core::ParamVisitor& v) {
  v.field("kp", &kp,
          {.doc = "proportional gain, rad of steering per unit of error", .min = -1e3, .max = 1e3});
  v.field("ki", &ki, {.doc = "integral gain, per second", .min = -1e3, .max = 1e3});
  v.field("kd", &kd, {.doc = "derivative gain, s", .min = -1e3, .max = 1e3});
  v.field("integral_limit_rad", &integral_limit_rad,
          {.doc = "the integral term's share of the output at most, rad", .min = 0, .max = 10});
}

void SlalomParams::visit(core::ParamVisitor& v) {
  v.field(
      "trigger_m", &trigger_m,
      {.doc = "distance from a slalom board at which the turn starts, m", .min = 0.05, .max = 100});
  v.field("turn_deg", &turn_deg,
          {.doc = "heading change of the turn and of the turn back, deg", .min = 1, .max = 170});
  v.field("straight_m", &straight_m,
          {.doc = "straight between the turn and the turn back, m", .min = 0, .max = 100});
  v.field("column_share", &column_share,
          {.doc = "distance between the board's column disks, share of its side",
           .min = 0.01,
           .max = 1});
  v.field("low_turn_deg", &low_turn_deg,
          {.doc = "the turn a board asks for with its single disk below the middle, deg",
           .min = 1,
           .max = 180});
  v.field("high_turn_deg", &high_turn_deg,
          {.doc = "the turn a board asks for with its single disk above the middle, deg",
           .min = 1,
           .max = 180});
}

void GateControllerParams::visit(core::ParamVisitor& v) {
  v.field("cruise_speed_mps", &cruise_speed_mps,
          {.doc = "speed while a pattern is in view, m/s", .min = 0.0, .max = 50});
  core::visitGroup(v, "lateral", "PID on D_y, the pattern's bearing from its reference (rad)",
                   lateral);
  core::visitGroup(v, "deformation",
                   "PID on delta_y, the pattern's left column height over its right's, minus 1",
                   deformation);
  v.field("reference_x_px", &reference_x_px,
          {.doc = "the reference pattern's centre column, px; < 0: the image centre",
           .min = -1,
           .max = 1e5});
  v.field("max_steer_deg", &max_steer_deg,
          {.doc = "the vehicle's steering lock, deg", .min = 1, .max = 80});
  v.field("wheelbase_m", &wheelbase_m,
          {.doc = "the vehicle's wheelbase (for the slalom's turns), m", .min = 0.01, .max = 10});
  v.field("max_lateral_acceleration_mps2", &max_lateral_acceleration_mps2,
          {.doc = "the tyres' grip: slalom turns no tighter than speed^2 / this; 0: the lock's",
           .min = 0,
           .max = 1000});
  v.field("coast_s", &coast_s,
          {.doc = "pattern lost: straight on at speed this long, s", .min = 0, .max = 60});
  v.field("stop_s", &stop_s,
          {.doc = "then from cruise speed to a stop over this, s", .min = 0.01, .max = 60});
  v.field("deformation_filter_s", &deformation_filter_s,
          {.doc = "delta_y's low-pass time constant, s", .min = 0, .max = 10});
  v.field("board_m", &board_m, {.doc = "side of the patterns' boards, m", .min = 0.01, .max = 10});
  v.field(
      "gate_row_share", &gate_row_share,
      {.doc = "distance between a gate's disk rows, share of its board", .min = 0.01, .max = 1});
  v.field("commit_m", &commit_m,
          {.doc = "a gate lost within this distance is driven through straight, m",
           .min = 0,
           .max = 100});
  v.field(
      "pass_margin_m", &pass_margin_m,
      {.doc = "straight on this far beyond a lost gate's last distance, m", .min = 0, .max = 100});
  core::visitGroup(v, "slalom", "slalom boards: when and how to turn", slalom);
}

double lateralError_rad(const PatternObservation& pattern, const Lens& lens,
                        double reference_x_px) {
  if (pattern.disks_px.empty()) return 0.0;
  double x = 0.0;
  for (const Eigen::Vector2d& disk : pattern.disks_px) x += disk.x();
  x /= static_cast<double>(pattern.disks_px.size());
  const double reference = reference_x_px < 0.0 ? lens.cx : reference_x_px;
  return std::atan((x - reference) / lens.fx);
}

double patternDistance_m(const PatternObservation& pattern, const Lens& lens,
                         const GateControllerParams& params) {
  const auto& d = pattern.disks_px;
  double spacing_px = 0.0, share = 0.0;
  if (pattern.kind == Pattern::kGate && d.size() == 4) {
    spacing_px = 0.5 * (d[2].y() - d[0].y() + d[3].y() - d[1].y());
    share = params.gate_row_share;
  } else if ((pattern.kind == Pattern::kSlalomLeft || pattern.kind == Pattern::kSlalomRight) &&
             d.size() == 3) {
    spacing_px = std::abs(d[1].y() - d[0].y());
    share = params.slalom.column_share;
  }
  return spacing_px > 0.0 ? lens.fy * share * params.board_m / spacing_px : 0.0;
}

double deformationOf(const PatternObservation& pattern) {
  if (pattern.kind != Pattern::kGate || pattern.disks_px.size() != 4) return 0.0;
  const auto& d = pattern.disks_px;
  const double left = d[2].y() - d[0].y(), right = d[3].y() - d[1].y();
  if (!(left > 0.0) || !(right > 0.0)) return 0.0;
  return left / right - 1.0;
}

double boardTurn_deg(const PatternObservation& pattern, const SlalomParams& params) {
  const bool slalom = pattern.kind == Pattern::kSlalomLeft || pattern.kind == Pattern::kSlalomRight;
  if (!slalom || pattern.disks_px.size() != 3) return 0.0;
  const auto& d = pattern.disks_px;  // column top, column bottom, tip
  const double column_px = d[1].y() - d[0].y();
  if (!(column_px > 0.0)) return 0.0;
  const double tip_share = (d[2].y() - d[0].y()) / column_px;
  if (tip_share < 0.375) return params.high_turn_deg;
  if (tip_share > 0.625) return params.low_turn_deg;
  return 0.0;
}

double GateController::Pid::step(const PidGains& gains, double error, double dt_s) {
  double derivative = 0.0;
  if (has_previous && dt_s > 0.0) {
    integral += error * dt_s;
    derivative = (error - previous) / dt_s;
  }
  previous = error;
  has_previous = true;
  double integral_term = gains.ki * integral;
  if (std::abs(integral_term) > gains.integral_limit_rad) {
    // Anti-windup: hold the integral where its term saturates.
    integral_term = std::copysign(gains.integral_limit_rad, integral_term);
    if (gains.ki != 0.0) integral = integral_term / gains.ki;
  }
  return gains.kp * error + integral_term + gains.kd * derivative;
}

GateController::GateController(const GateControllerParams& params) : params_(params) {
  core::validateParams([this](core::ParamVisitor& v) { params_.visit(v); }, "control");
}

SteeringCommand GateController::throughGate(std::int64_t utime) {
  SteeringCommand command;
  command.mode = DriveMode::kCoasting;
  command.speed_mps = params_.cruise_speed_mps;
  if (utime >= commit_until_) {
    commit_until_ = -1;
    last_seen_utime_ = utime;
  }
  return command;
}

SteeringCommand GateController::lost(std::int64_t utime) {
  lateral_.reset();
  deformation_.reset();
  deformation_filtered_ = 0.0;
  SteeringCommand command;
  if (!moving_ || last_seen_utime_ < 0) return command;  // never started: stay
  const double t = seconds(utime - last_seen_utime_);
  const double cruise = params_.cruise_speed_mps;
  if (t <= params_.coast_s) {
    command.mode = DriveMode::kCoasting;
    command.speed_mps = cruise;
  } else if (t < params_.coast_s + params_.stop_s) {
    command.mode = DriveMode::kStopping;
    command.speed_mps = cruise * (1.0 - (t - params_.coast_s) / params_.stop_s);
  } else {
    moving_ = false;
  }
  return command;
}

SteeringCommand GateController::manoeuvre(std::int64_t utime) {
  const double t = seconds(utime - manoeuvre_start_);
  const double lock = manoeuvre_steer_rad_;
  SteeringCommand command;
  command.mode = DriveMode::kManoeuvre;
  command.speed_mps = params_.cruise_speed_mps;
  if (t < turn_s_) {
    command.steer_rad = manoeuvre_side_ * lock;
  } else if (t < turn_s_ + straight_s_) {
    command.steer_rad = 0.0;
  } else {
    // Turning back towards the line of boards (or, after a turn, straight on)
    // until the next board is in view (update() takes it from there), blind
    // no longer than lost() allows.
    in_manoeuvre_ = false;
    returning_ = !go_on_;
    last_seen_utime_ = utime;
    return returning_ ? returnTurn(utime) : lost(utime);
  }
  return command;
}

SteeringCommand GateController::returnTurn(std::int64_t utime) {
  SteeringCommand command = lost(utime);
  if (command.speed_mps > 0.0) {
    command.steer_rad = -manoeuvre_side_ * manoeuvre_steer_rad_;
    command.mode = DriveMode::kManoeuvre;
  } else {
    returning_ = false;
  }
  return command;
}

SteeringCommand GateController::update(const PatternObservation& pattern, const Lens& lens) {
  const double dt_s = previous_utime_ < 0 ? 0.0 : seconds(pattern.utime - previous_utime_);
  previous_utime_ = pattern.utime;
  if (in_manoeuvre_) return manoeuvre(pattern.utime);
  if (commit_until_ >= 0) return throughGate(pattern.utime);
  const bool seen = pattern.kind != Pattern::kNone && !pattern.disks_px.empty();
  // The gate's board has left the image, or what is seen now is another
  // pattern further off (the next gate): drive through the one tracked.
  const bool gate_left =
      !seen || patternDistance_m(pattern, lens, params_) > gate_distance_m_ + params_.pass_margin_m;
  if (gate_left && tracking_gate_ && gate_distance_m_ > 0.0 &&
      gate_distance_m_ <= params_.commit_m) {
    tracking_gate_ = false;
    commit_until_ =
        pattern.utime + static_cast<std::int64_t>(1e6 * (gate_distance_m_ + params_.pass_margin_m) /
                                                  std::max(params_.cruise_speed_mps, 0.01));
    lateral_.reset();
    deformation_.reset();
    deformation_filtered_ = 0.0;
    return throughGate(pattern.utime);
  }
  tracking_gate_ = false;
  if (!seen) return returning_ ? returnTurn(pattern.utime) : lost(pattern.utime);
  returning_ = false;

  last_seen_utime_ = pattern.utime;
  moving_ = true;
  SteeringCommand command;
  command.mode = DriveMode::kTracking;
  command.speed_mps = params_.cruise_speed_mps;
  command.lateral_error_rad = lateralError_rad(pattern, lens, params_.reference_x_px);
  const double raw_deformation = deformationOf(pattern);
  const double alpha = params_.deformation_filter_s > 0.0 && dt_s > 0.0
                           ? dt_s / (params_.deformation_filter_s + dt_s)
                           : 1.0;
  deformation_filtered_ += alpha * (raw_deformation - deformation_filtered_);
  command.deformation = deformation_filtered_;
  command.board_distance_m = patternDistance_m(pattern, lens, params_);
  const double lock = params_.max_steer_deg * kDeg;
  command.steer_rad =
      std::clamp(lateral_.step(params_.lateral, command.lateral_error_rad, dt_s) +
                     deformation_.step(params_.deformation, command.deformation, dt_s),
                 -lock, lock);
  if (pattern.kind == Pattern::kGate) {
    tracking_gate_ = true;
    gate_distance_m_ = command.board_distance_m;
  }
  const bool slalom = pattern.kind == Pattern::kSlalomLeft || pattern.kind == Pattern::kSlalomRight;
  if (slalom) {
    if (command.board_distance_m > 0.0 && command.board_distance_m <= params_.slalom.trigger_m) {
      // A turn at full lock on a circle of radius L / tan(lock), or as tight
      // as the grip allows at this speed.
      const double speed = std::max(params_.cruise_speed_mps, 0.01);
      double radius_m = params_.wheelbase_m / std::tan(lock);
      if (params_.max_lateral_acceleration_mps2 > 0.0) {
        radius_m = std::max(radius_m, speed * speed / params_.max_lateral_acceleration_mps2);
      }
      manoeuvre_steer_rad_ = std::atan(params_.wheelbase_m / radius_m);
      const double asked_deg = boardTurn_deg(pattern, params_.slalom);
      go_on_ = asked_deg > 0.0;
      turn_s_ = (go_on_ ? asked_deg : params_.slalom.turn_deg) * kDeg * radius_m / speed;
      straight_s_ = go_on_ ? 0.0 : params_.slalom.straight_m / speed;
      manoeuvre_side_ = pattern.kind == Pattern::kSlalomRight ? 1.0 : -1.0;
      manoeuvre_start_ = pattern.utime;
      in_manoeuvre_ = true;
      lateral_.reset();
      deformation_.reset();
      SteeringCommand turning = manoeuvre(pattern.utime);
      turning.board_distance_m = command.board_distance_m;
      return turning;
    }
  }
  return command;
}

}  // namespace nadir::control
