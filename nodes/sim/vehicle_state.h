#pragma once
// The true state of a simulated vehicle: what sensors sample and POSE_TRUTH carries.

#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace nadir::sim {

struct VehicleState {
  // Sim time, microseconds.
  std::int64_t utime = 0;
  // Body origin in the world frame (local NED), m; its velocity and acceleration, m/s, m/s^2.
  Eigen::Vector3d p_ned_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_ned_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d a_ned_mps2 = Eigen::Vector3d::Zero();
  // R_world_body (body FRD) and the body's angular velocity in the body frame, rad/s.
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();
  Eigen::Vector3d omega_body_rps = Eigen::Vector3d::Zero();
};

// Standard gravity, m/s^2; down in NED.
inline constexpr double kGravity_mps2 = 9.80665;

}  // namespace nadir::sim
