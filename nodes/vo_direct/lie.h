#pragma once
// SE(3) increments as (translation, rotation) 6-vectors, applied on the left:
// T <- exp(xi) T. The exponential and the adjoint in that ordering.

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace nadir::vo {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

inline Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

inline Eigen::Isometry3d se3Exp(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>();
  const Eigen::Vector3d omega = xi.tail<3>();
  const double theta = omega.norm();
  const Eigen::Matrix3d W = skew(omega);
  Eigen::Matrix3d R, V;
  if (theta < 1e-8) {
    R = Eigen::Matrix3d::Identity() + W;
    V = Eigen::Matrix3d::Identity() + 0.5 * W;
  } else {
    const double a = std::sin(theta) / theta;
    const double b = (1 - std::cos(theta)) / (theta * theta);
    const double c = (1 - a) / (theta * theta);
    R = Eigen::Matrix3d::Identity() + a * W + b * W * W;
    V = Eigen::Matrix3d::Identity() + b * W + c * W * W;
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(R).normalized().toRotationMatrix();
  T.translation() = V * rho;
  return T;
}

// The nearest rotation to T's linear part. Poses here are products of many
// increments, predictions and inverses; an Isometry3d's inverse assumes an
// orthonormal rotation, so rounding that is never removed grows with every
// product (by about three times a frame through the motion model).
inline Eigen::Isometry3d orthonormalized(const Eigen::Isometry3d& T) {
  Eigen::Isometry3d out = T;
  out.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
  return out;
}

// Ad(T) such that T exp(xi) = exp(Ad(T) xi) T.
inline Matrix6d adjoint(const Eigen::Isometry3d& T) {
  Matrix6d A = Matrix6d::Zero();
  const Eigen::Matrix3d R = T.linear();
  A.topLeftCorner<3, 3>() = R;
  A.topRightCorner<3, 3>() = skew(T.translation()) * R;
  A.bottomRightCorner<3, 3>() = R;
  return A;
}

}  // namespace nadir::vo
