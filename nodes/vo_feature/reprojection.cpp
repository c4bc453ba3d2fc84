#include "nodes/vo_feature/reprojection.h"

namespace nadir::vo {

bool reprojectionResidual(const BaIntrinsics& K, const Eigen::Vector2d& px, double inv_sigma,
                          const Eigen::Matrix3d& R_world_cam, const Eigen::Vector3d& p_world_cam_m,
                          const Eigen::Vector3d& p_world_m, Eigen::Vector2d& residual,
                          Eigen::Matrix<double, 2, 6>* d_camera,
                          Eigen::Matrix<double, 2, 3>* d_point) {
  const Eigen::Vector3d p_cam = R_world_cam.transpose() * (p_world_m - p_world_cam_m);
  if (!(p_cam.z() > 0.0)) {
    return false;
  }
  const double inv_z = 1.0 / p_cam.z();
  const double x_n = p_cam.x() * inv_z;
  const double y_n = p_cam.y() * inv_z;
  residual = Eigen::Vector2d((K.fx * x_n + K.cx - px.x()) * inv_sigma,
                             (K.fy * y_n + K.cy - px.y()) * inv_sigma);
  if (d_camera == nullptr && d_point == nullptr) {
    return true;
  }
  // d r / d p_cam.
  const double sx = K.fx * inv_z * inv_sigma;
  const double sy = K.fy * inv_z * inv_sigma;
  Eigen::Matrix<double, 2, 3> d_p;
  d_p << sx, 0.0, -sx * x_n, 0.0, sy, -sy * y_n;
  // p_cam = R^T (p - c): d / d p = R^T, d / d c = -R^T, and with R Exp(dtheta),
  // p_cam = Exp(-dtheta) R^T (p - c), d / d dtheta = [p_cam]x.
  const Eigen::Matrix<double, 2, 3> d_v = d_p * R_world_cam.transpose();
  if (d_point != nullptr) {
    *d_point = d_v;
  }
  if (d_camera != nullptr) {
    Eigen::Matrix3d skew_p;
    skew_p << 0.0, -p_cam.z(), p_cam.y(), p_cam.z(), 0.0, -p_cam.x(), -p_cam.y(), p_cam.x(), 0.0;
    d_camera->leftCols<3>() = d_p * skew_p;
    d_camera->rightCols<3>() = -d_v;
  }
  return true;
}

}  // namespace nadir::vo
