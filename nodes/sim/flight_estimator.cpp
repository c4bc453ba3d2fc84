#include "nodes/sim/flight_estimator.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/frames.h"
#include "nodes/sim/vehicle_state.h"

namespace nadir::sim {
namespace {

constexpr double kRadPerDeg = std::numbers::pi / 180.0;
// A gyro bias estimate beyond this is the filter running away, not a bias.
constexpr double kMaxGyroBias_rps = 0.1;

Eigen::Vector3d horizontal(const Eigen::Vector3d& v) { return {v.x(), v.y(), 0.0}; }

// The heading that the field seen in the body gives, with the tilt of
// q_world_body taken out: psi = D - atan2(m_level_y, m_level_x).
double headingFromField(const Eigen::Vector3d& field_body_ut,
                        const Eigen::Quaterniond& q_world_body, double declination_rad) {
  const double yaw = core::rpyFromQuaternion(q_world_body).yaw_rad;
  const Eigen::Vector3d level =
      Eigen::AngleAxisd(-yaw, Eigen::Vector3d::UnitZ()) * (q_world_body * field_body_ut);
  return core::wrapAngle_rad(declination_rad - std::atan2(level.y(), level.x()));
}

bool hasFix(const msg::Gps& gps) { return gps.fix != msg::GpsFix::NONE; }

}  // namespace

void AhrsParams::visit(core::ParamVisitor& v) {
  v.field("estimator", &estimator,
          {.doc = "complementary (a flight controller's filters) or ideal (NAV_* are the truth)",
           .choices = {"complementary", "ideal"}});
  v.field("tilt_gain_per_s", &tilt_gain_per_s,
          {.doc = "roll/pitch correction, rad/s per rad", .min = 0, .max = 100});
  v.field("heading_gain_per_s", &heading_gain_per_s,
          {.doc = "heading correction from the magnetometer, rad/s per rad", .min = 0, .max = 100});
  v.field("bias_gain_per_s2", &bias_gain_per_s2,
          {.doc = "gyro bias estimate, rad/s per rad of error per s", .min = 0, .max = 100});
  v.field("declination_deg", &declination_deg,
          {.doc = "declination the flight controller assumes, deg", .min = -180, .max = 180});
  v.field("gps_acceleration", &gps_acceleration,
          {.doc = "take the GPS-measured acceleration out of the accelerometer's tilt"});
  v.field("accel_gate", &accel_gate,
          {.doc = "without GPS: no tilt correction when |f| departs from g by this fraction",
           .min = 1e-3,
           .max = 10});
  v.field("horizontal_time_constant_s", &horizontal_time_constant_s,
          {.doc = "time constant of the GPS position filter, s", .min = 0.05, .max = 1000});
  v.field("vertical_time_constant_s", &vertical_time_constant_s,
          {.doc = "time constant of the barometric altitude filter, s", .min = 0.05, .max = 1000});
}

FlightEstimator::FlightEstimator(const AhrsParams& params, const core::LocalNedFrame& frame)
    : params_(params), frame_(frame), declination_rad_(params.declination_deg * kRadPerDeg) {}

void FlightEstimator::initialiseAttitude(const Eigen::Vector3d& field_body_ut) {
  // f_body = -g (-sin(pitch), sin(roll) cos(pitch), cos(roll) cos(pitch)).
  const Eigen::Vector3d& f = *first_specific_force_;
  core::RollPitchYaw rpy;
  rpy.roll_rad = std::atan2(-f.y(), -f.z());
  rpy.pitch_rad = std::atan2(f.x(), std::hypot(f.y(), f.z()));
  rpy.yaw_rad = 0.0;
  const Eigen::Quaterniond tilt = core::quaternionFromRpy(rpy);
  rpy.yaw_rad = headingFromField(field_body_ut, tilt, declination_rad_);
  q_world_body_ = core::quaternionFromRpy(rpy);
  has_attitude_ = true;
}

void FlightEstimator::addImu(const msg::Imu& imu) {
  const Eigen::Vector3d& f_body = imu.linear_acceleration_mps2;
  if (!has_attitude_) {
    first_specific_force_ = f_body;
    imu_utime_ = imu.utime;
    rates_body_rps_ = imu.angular_velocity_rps;
    return;
  }
  const double dt_s = std::max(0.0, static_cast<double>(imu.utime - imu_utime_) * 1e-6);
  imu_utime_ = imu.utime;
  if (!tilt_from_gps_ && f_body.norm() > 0.0) {
    // Without a GPS acceleration: the accelerometer is taken for gravity
    // alone, the less the further its magnitude is from g.
    const double load = std::fabs(f_body.norm() / kGravity_mps2 - 1.0);
    const double weight = std::clamp(1.0 - load / params_.accel_gate, 0.0, 1.0);
    const Eigen::Vector3d seen = q_world_body_ * f_body.normalized();
    tilt_error_world_ = weight * horizontal(seen.cross(-Eigen::Vector3d::UnitZ()));
  }
  // Mahony: omega = gyro - bias + kP e; d(bias)/dt = -kI e (e in the body).
  const Eigen::Vector3d error_body =
      q_world_body_.conjugate() * (params_.tilt_gain_per_s * tilt_error_world_ +
                                   params_.heading_gain_per_s * heading_error_world_);
  const Eigen::Vector3d integral_body =
      q_world_body_.conjugate() * (tilt_error_world_ + heading_error_world_);
  gyro_bias_rps_ -= params_.bias_gain_per_s2 * integral_body * dt_s;
  gyro_bias_rps_ = gyro_bias_rps_.cwiseMax(-kMaxGyroBias_rps).cwiseMin(kMaxGyroBias_rps);
  rates_body_rps_ = imu.angular_velocity_rps - gyro_bias_rps_;
  const Eigen::Vector3d omega = rates_body_rps_ + error_body;
  const double angle = omega.norm() * dt_s;
  if (angle > 0.0)
    q_world_body_ =
        (q_world_body_ * Eigen::Quaterniond(Eigen::AngleAxisd(angle, omega.normalized())))
            .normalized();

  const Eigen::Vector3d f_ned = q_world_body_ * f_body;
  specific_force_sum_ned_ += f_ned * dt_s;
  if (has_position_) {
    const Eigen::Vector3d a_ned =
        f_ned + Eigen::Vector3d(0.0, 0.0, kGravity_mps2) + accel_correction_ned_mps2_;
    p_ned_m_ += v_ned_mps_ * dt_s + 0.5 * a_ned * dt_s * dt_s;
    v_ned_mps_ += a_ned * dt_s;
  }
}

void FlightEstimator::addMagnetometer(const msg::Magnetometer& mag) {
  if (!has_attitude_) {
    if (first_specific_force_) initialiseAttitude(mag.field_body_ut);
    return;
  }
  const double yaw = core::rpyFromQuaternion(q_world_body_).yaw_rad;
  const double error = core::wrapAngle_rad(
      headingFromField(mag.field_body_ut, q_world_body_, declination_rad_) - yaw);
  heading_error_world_ = Eigen::Vector3d(0.0, 0.0, error);
}

void FlightEstimator::addGps(const msg::Gps& gps) {
  if (!hasFix(gps)) {
    // Tilt from the accelerometer alone until the next pair of fixes.
    previous_fix_.reset();
    tilt_from_gps_ = false;
    return;
  }
  if (params_.gps_acceleration && has_attitude_ && previous_fix_) {
    // Over the interval: sum of f_ned dt against the GPS's dv - g dt.
    const double dt_s = static_cast<double>(gps.utime - previous_fix_->utime) * 1e-6;
    const Eigen::Vector3d expected = gps.velocity_ned_mps - previous_fix_->velocity_ned_mps -
                                     Eigen::Vector3d(0.0, 0.0, kGravity_mps2 * dt_s);
    if (dt_s > 0.0 && specific_force_sum_ned_.norm() > 0.0) {
      tilt_error_world_ =
          horizontal(specific_force_sum_ned_.normalized().cross(expected.normalized()));
      tilt_from_gps_ = true;
    }
  }
  specific_force_sum_ned_.setZero();
  previous_fix_ = gps;

  const Eigen::Vector3d p_gps = frame_.nedFromGeodetic({gps.lat_rad, gps.lon_rad, gps.alt_m});
  if (!has_position_) {
    if (!has_attitude_) return;
    p_ned_m_ = p_gps;
    v_ned_mps_ = gps.velocity_ned_mps;
    has_position_ = true;
    horizontal_utime_ = vertical_utime_ = gps.utime;
    return;
  }
  const double dt_s = static_cast<double>(gps.utime - horizontal_utime_) * 1e-6;
  horizontal_utime_ = gps.utime;
  correctAxis(0, p_gps.x(), params_.horizontal_time_constant_s, dt_s);
  correctAxis(1, p_gps.y(), params_.horizontal_time_constant_s, dt_s);
  if (!vertical_from_baro_) {
    correctAxis(2, p_gps.z(), params_.vertical_time_constant_s, dt_s);
    vertical_utime_ = gps.utime;
  }
}

void FlightEstimator::addBaro(const msg::Baro& baro) {
  vertical_from_baro_ = true;
  if (!has_position_) return;
  const double dt_s = static_cast<double>(baro.utime - vertical_utime_) * 1e-6;
  vertical_utime_ = baro.utime;
  correctAxis(2, frame_.origin().alt_m - baro.altitude_m, params_.vertical_time_constant_s, dt_s);
}

void FlightEstimator::correctAxis(int axis, double measured_m, double time_constant_s,
                                  double dt_s) {
  // Gains 3/tau, 3/tau^2, 1/tau^3: all three poles at -1/tau.
  const double error = measured_m - p_ned_m_[axis];
  const double step = std::min(dt_s / time_constant_s, 1.0 / 3.0);
  p_ned_m_[axis] += 3.0 * error * step;
  v_ned_mps_[axis] += 3.0 * error * step / time_constant_s;
  accel_correction_ned_mps2_[axis] += error * step / (time_constant_s * time_constant_s);
}

}  // namespace nadir::sim
