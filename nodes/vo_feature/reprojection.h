#pragma once
// The bundle adjustment's reprojection residual with its Jacobians in closed
// form (docs/vo_feature.md, "Local bundle adjustment").

#include <Eigen/Core>

namespace nadir::vo {

// Undistorted pinhole intrinsics, px.
struct BaIntrinsics {
  double fx = 1.0;
  double fy = 1.0;
  double cx = 0.0;
  double cy = 0.0;
};

// r = (pi(K, R_world_cam^T (p_world_m - p_world_cam_m)) - px) * inv_sigma.
// d_camera (2 x 6): with respect to a rotation applied on the camera's side,
// R_world_cam Exp(dtheta), then to the camera centre; d_point (2 x 3): to the
// point. Each is written when not null. False, with nothing written, when the
// point is not in front of the camera.
bool reprojectionResidual(const BaIntrinsics& K, const Eigen::Vector2d& px, double inv_sigma,
                          const Eigen::Matrix3d& R_world_cam, const Eigen::Vector3d& p_world_cam_m,
                          const Eigen::Vector3d& p_world_m, Eigen::Vector2d& residual,
                          Eigen::Matrix<double, 2, 6>* d_camera,
                          Eigen::Matrix<double, 2, 3>* d_point);

}  // namespace nadir::vo
