#include "core/frames.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace nadir::core {

Eigen::Matrix3d rotationFromRpy(const RollPitchYaw& rpy) {
  return quaternionFromRpy(rpy).toRotationMatrix();
}

Eigen::Quaterniond quaternionFromRpy(const RollPitchYaw& rpy) {
  return Eigen::AngleAxisd(rpy.yaw_rad, Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(rpy.pitch_rad, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(rpy.roll_rad, Eigen::Vector3d::UnitX());
}

RollPitchYaw rpyFromRotation(const Eigen::Matrix3d& R_world_body) {
  const Eigen::Matrix3d& R = R_world_body;
  RollPitchYaw rpy;
  // Roll from the last row (cos(pitch) * (.., sin(roll), cos(roll))); then strip it
  // and read yaw and pitch from M = Rz(yaw) Ry(pitch), whose entries hold them
  // without asin. This reproduces R to rounding even next to pitch = +-90 deg.
  const double roll_scale = std::hypot(R(2, 1), R(2, 2));
  constexpr double kGimbalLock = 1e-12;
  rpy.roll_rad = roll_scale > kGimbalLock ? std::atan2(R(2, 1), R(2, 2)) : 0.0;
  const Eigen::Matrix3d M =
      R * Eigen::AngleAxisd(rpy.roll_rad, Eigen::Vector3d::UnitX()).toRotationMatrix().transpose();
  rpy.yaw_rad = std::atan2(-M(0, 1), M(1, 1));
  rpy.pitch_rad = std::atan2(-M(2, 0), M(2, 2));
  return rpy;
}

RollPitchYaw rpyFromQuaternion(const Eigen::Quaterniond& q_world_body) {
  return rpyFromRotation(q_world_body.normalized().toRotationMatrix());
}

Eigen::Matrix3d rotationBodyFromDownCamera() {
  Eigen::Matrix3d R_body_cam;
  R_body_cam.col(0) = Eigen::Vector3d(0, 1, 0);
  R_body_cam.col(1) = Eigen::Vector3d(-1, 0, 0);
  R_body_cam.col(2) = Eigen::Vector3d(0, 0, 1);
  return R_body_cam;
}

Eigen::Quaterniond quaternionFromWire(const double wxyz[4]) {
  Eigen::Quaterniond q(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
  const double norm = q.norm();
  if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-3) {
    throw std::invalid_argument("quaternion (" + std::to_string(wxyz[0]) + ", " +
                                std::to_string(wxyz[1]) + ", " + std::to_string(wxyz[2]) + ", " +
                                std::to_string(wxyz[3]) + ") is not a unit quaternion");
  }
  return q.normalized();
}

void quaternionToWire(const Eigen::Quaterniond& q, double wxyz[4]) {
  wxyz[0] = q.w();
  wxyz[1] = q.x();
  wxyz[2] = q.y();
  wxyz[3] = q.z();
}

}  // namespace nadir::core
