#pragma once
// Rotation conventions, one for the whole project.
//
// World frame: local NED. Body frame: FRD (x forward, y right, z down).
// Camera frame: OpenCV optical (x right, y down the image, z along the optical axis).
//
// Euler angles are aerospace Z-Y-X (yaw, then pitch, then roll, each about the
// axis as already rotated):
//   R_world_body = Rz(yaw) * Ry(pitch) * Rx(roll)
// R_world_body rotates body-frame vectors into the world frame. Positive roll
// lowers the right wing, positive pitch raises the nose, positive yaw turns the
// nose from north towards east. Quaternions are Hamilton, w first on the wire.

#include <cmath>
#include <numbers>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace nadir::core {

struct RollPitchYaw {
  double roll_rad = 0.0;
  double pitch_rad = 0.0;
  double yaw_rad = 0.0;
};

Eigen::Matrix3d rotationFromRpy(const RollPitchYaw& rpy);
Eigen::Quaterniond quaternionFromRpy(const RollPitchYaw& rpy);

// Inverse of rotationFromRpy with pitch in [-pi/2, pi/2] and roll, yaw in
// (-pi, pi]. At pitch = +-pi/2 (gimbal lock) roll is set to 0 and yaw carries
// the whole rotation about the vertical.
RollPitchYaw rpyFromRotation(const Eigen::Matrix3d& R_world_body);
RollPitchYaw rpyFromQuaternion(const Eigen::Quaterniond& q_world_body);

// An angle brought into [-pi, pi].
inline double wrapAngle_rad(double angle_rad) {
  return std::remainder(angle_rad, 2.0 * std::numbers::pi);
}

// R_body_cam of a camera looking straight down along body +z with the top of
// the image towards the nose: camera x = body y, camera y = -body x.
Eigen::Matrix3d rotationBodyFromDownCamera();

// Wire format (w, x, y, z). fromWire normalises and throws std::invalid_argument
// if the norm is far from 1 (not a rotation).
Eigen::Quaterniond quaternionFromWire(const double wxyz[4]);
void quaternionToWire(const Eigen::Quaterniond& q, double wxyz[4]);

}  // namespace nadir::core
