#pragma once
// What a small flight controller knows of its own state: attitude and gyro
// bias from a nonlinear complementary filter on SO(3) (Mahony, Hamel and
// Pflimlin's explicit filter, as in ArduPilot's DCM), position and velocity
// from a third-order complementary filter per NED axis. Fed the simulated
// sensors, so that NAV_* carry the errors a real one's do. Plain structs in
// and out, no LCM; docs/simulator.md gives the equations and why.

#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/geodesy.h"
#include "core/params.h"
#include "lcmtypes/messages.h"

namespace nadir::sim {

struct AhrsParams {
  // "complementary": the filters below; "ideal": NAV_* are the truth.
  std::string estimator = "complementary";
  // Proportional gains of the attitude corrections, rad/s per rad of error.
  double tilt_gain_per_s = 0.2;
  double heading_gain_per_s = 0.2;
  // Integral gain: the gyro bias estimate moves at this times the error, 1/s^2.
  double bias_gain_per_s2 = 0.0087;
  // The declination the flight controller assumes (its table's), deg.
  double declination_deg = -4.0;
  // With a GPS fix, take the vehicle's own acceleration (from the GPS
  // velocity) out of the accelerometer before it corrects the tilt.
  bool gps_acceleration = true;
  // Without it, the accelerometer's tilt counts less the more its magnitude
  // departs from g, down to nothing at this fraction of g (a turn's load).
  double accel_gate = 0.1;
  // Time constants of the position filters (GPS horizontally, the barometer
  // vertically), s.
  double horizontal_time_constant_s = 2.5;
  double vertical_time_constant_s = 5.0;

  bool ideal() const { return estimator == "ideal"; }
  // Throws core::ParamError for an estimator not in {complementary, ideal}.
  void visit(core::ParamVisitor& v);
};

class FlightEstimator {
 public:
  // The position is estimated in frame's NED; start_altitude_m is the
  // ellipsoid altitude of the NED origin's down zero (the barometer's reference).
  FlightEstimator(const AhrsParams& params, const core::LocalNedFrame& frame);

  // Samples in time order. The attitude starts at the first magnetometer
  // sample after an IMU sample (tilt from the accelerometer, heading from the
  // magnetometer); the position at the first GPS fix after that.
  void addImu(const msg::Imu& imu);
  void addMagnetometer(const msg::Magnetometer& mag);
  void addGps(const msg::Gps& gps);
  void addBaro(const msg::Baro& baro);

  bool hasAttitude() const { return has_attitude_; }
  bool hasPosition() const { return has_position_; }
  const Eigen::Quaterniond& q_world_body() const { return q_world_body_; }
  const Eigen::Vector3d& gyroBias_rps() const { return gyro_bias_rps_; }
  // The latest gyro reading less the estimated bias, body FRD.
  const Eigen::Vector3d& rates_body_rps() const { return rates_body_rps_; }
  const Eigen::Vector3d& p_ned_m() const { return p_ned_m_; }
  const Eigen::Vector3d& v_ned_mps() const { return v_ned_mps_; }
  // The estimated NED-frame correction of the accelerometer, m/s^2.
  const Eigen::Vector3d& accelCorrection_ned_mps2() const { return accel_correction_ned_mps2_; }

 private:
  void initialiseAttitude(const Eigen::Vector3d& field_body_ut);
  void correctAxis(int axis, double measured_m, double time_constant_s, double dt_s);

  AhrsParams params_;
  core::LocalNedFrame frame_;
  double declination_rad_;

  bool has_attitude_ = false;
  std::optional<Eigen::Vector3d> first_specific_force_;
  std::int64_t imu_utime_ = 0;
  Eigen::Quaterniond q_world_body_ = Eigen::Quaterniond::Identity();
  Eigen::Vector3d gyro_bias_rps_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d rates_body_rps_ = Eigen::Vector3d::Zero();
  // The corrections, world frame, rad: held until the next measurement.
  Eigen::Vector3d tilt_error_world_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d heading_error_world_ = Eigen::Vector3d::Zero();
  bool tilt_from_gps_ = false;
  // The accelerometer rotated into NED and summed since the last GPS fix, m/s.
  Eigen::Vector3d specific_force_sum_ned_ = Eigen::Vector3d::Zero();
  std::optional<msg::Gps> previous_fix_;

  bool has_position_ = false;
  Eigen::Vector3d p_ned_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_ned_mps_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_correction_ned_mps2_ = Eigen::Vector3d::Zero();
  std::int64_t horizontal_utime_ = 0;
  std::int64_t vertical_utime_ = 0;
  bool vertical_from_baro_ = false;
};

}  // namespace nadir::sim
