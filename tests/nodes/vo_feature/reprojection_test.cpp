// The bundle adjustment's reprojection residual and its closed-form Jacobians
// (nodes/vo_feature/reprojection.h).

#include "nodes/vo_feature/reprojection.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <numbers>
#include <random>

namespace nadir::vo {
namespace {

const BaIntrinsics kK{.fx = 700.0, .fy = 650.0, .cx = 640.0, .cy = 480.0};

// The residual as Eigen transforms and a pinhole projects: the reference the
// closed form is checked against, written without it.
Eigen::Vector2d referenceResidual(const Eigen::Matrix3d& R_world_cam, const Eigen::Vector3d& centre,
                                  const Eigen::Vector3d& point, const Eigen::Vector2d& px,
                                  double inv_sigma) {
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  T_world_cam.linear() = R_world_cam;
  T_world_cam.translation() = centre;
  const Eigen::Vector3d p_cam = T_world_cam.inverse() * point;
  return (Eigen::Vector2d(kK.fx * p_cam.x() / p_cam.z() + kK.cx,
                          kK.fy * p_cam.y() / p_cam.z() + kK.cy) -
          px) *
         inv_sigma;
}

TEST(Reprojection, ResidualOfARotatedCameraWorkedOutByHand) {
  // The camera 90 deg about the world's z at (1, 2, 0): its x axis is the
  // world's y, its y the world's -x. The point (1, 5, 10) is 3 m along the
  // camera's x and 10 m ahead: u = 700 * 0.3 + 640 = 850, v = 480.
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(std::numbers::pi / 2.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Eigen::Vector2d r;
  ASSERT_TRUE(reprojectionResidual(kK, Eigen::Vector2d(848.0, 481.0), 0.5, R,
                                   Eigen::Vector3d(1.0, 2.0, 0.0), Eigen::Vector3d(1.0, 5.0, 10.0),
                                   r, nullptr, nullptr));
  EXPECT_NEAR(r.x(), (850.0 - 848.0) * 0.5, 1e-9);
  EXPECT_NEAR(r.y(), (480.0 - 481.0) * 0.5, 1e-9);
}

TEST(Reprojection, NothingForAPointBehindTheCamera) {
  Eigen::Vector2d r(7.0, 7.0);
  EXPECT_FALSE(reprojectionResidual(kK, Eigen::Vector2d(640, 480), 1.0, Eigen::Matrix3d::Identity(),
                                    Eigen::Vector3d::Zero(), Eigen::Vector3d(1.0, 1.0, -5.0), r,
                                    nullptr, nullptr));
  EXPECT_EQ(r, Eigen::Vector2d(7.0, 7.0));
}

TEST(Reprojection, JacobiansMatchCentralDifferencesOfTheReference) {
  // Random cameras and points in front of them (fixed seed); every column of
  // both Jacobians against central differences of referenceResidual, the
  // rotation perturbed on the camera's side: R Exp(h e_k).
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  constexpr double kStep = 1e-6;
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.6 * unit(rng), Eigen::Vector3d::UnitX()) *
                               Eigen::AngleAxisd(0.6 * unit(rng), Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(3.0 * unit(rng), Eigen::Vector3d::UnitZ()))
                                  .toRotationMatrix();
    const Eigen::Vector3d centre(50.0 * unit(rng), 50.0 * unit(rng), 20.0 * unit(rng));
    const Eigen::Vector3d ahead(100.0 * unit(rng), 80.0 * unit(rng), 150.0 + 100.0 * unit(rng));
    const Eigen::Vector3d point = R * ahead + centre;
    const Eigen::Vector2d px(640.0 + 300.0 * unit(rng), 480.0 + 200.0 * unit(rng));
    const double inv_sigma = 1.0 / 1.2;

    Eigen::Vector2d r;
    Eigen::Matrix<double, 2, 6> d_camera;
    Eigen::Matrix<double, 2, 3> d_point;
    ASSERT_TRUE(reprojectionResidual(kK, px, inv_sigma, R, centre, point, r, &d_camera, &d_point));
    EXPECT_LT((r - referenceResidual(R, centre, point, px, inv_sigma)).norm(), 1e-9);

    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d h = kStep * Eigen::Vector3d::Unit(k);
      const Eigen::Matrix3d R_plus = R * Eigen::AngleAxisd(kStep, Eigen::Vector3d::Unit(k));
      const Eigen::Matrix3d R_minus = R * Eigen::AngleAxisd(-kStep, Eigen::Vector3d::Unit(k));
      const Eigen::Vector2d d_rotation =
          (referenceResidual(R_plus, centre, point, px, inv_sigma) -
           referenceResidual(R_minus, centre, point, px, inv_sigma)) /
          (2.0 * kStep);
      const Eigen::Vector2d d_centre = (referenceResidual(R, centre + h, point, px, inv_sigma) -
                                        referenceResidual(R, centre - h, point, px, inv_sigma)) /
                                       (2.0 * kStep);
      const Eigen::Vector2d d_point_numeric =
          (referenceResidual(R, centre, point + h, px, inv_sigma) -
           referenceResidual(R, centre, point - h, px, inv_sigma)) /
          (2.0 * kStep);
      for (int row = 0; row < 2; ++row) {
        EXPECT_NEAR(d_camera(row, k), d_rotation[row], 1e-5 * (1.0 + std::abs(d_rotation[row])))
            << "rotation " << k << " trial " << trial;
        EXPECT_NEAR(d_camera(row, 3 + k), d_centre[row], 1e-5 * (1.0 + std::abs(d_centre[row])))
            << "centre " << k << " trial " << trial;
        EXPECT_NEAR(d_point(row, k), d_point_numeric[row],
                    1e-5 * (1.0 + std::abs(d_point_numeric[row])))
            << "point " << k << " trial " << trial;
      }
    }
  }
}

TEST(Reprojection, OnlyTheJacobiansAskedForAreWritten) {
  // As the solver asks for a fixed camera: the point's Jacobian only.
  Eigen::Vector2d r;
  Eigen::Matrix<double, 2, 3> d_point;
  ASSERT_TRUE(reprojectionResidual(kK, Eigen::Vector2d(640, 480), 1.0, Eigen::Matrix3d::Identity(),
                                   Eigen::Vector3d::Zero(), Eigen::Vector3d(3.0, -2.0, 100.0), r,
                                   nullptr, &d_point));
  // Identity rotation: d u / d x = fx / z, d u / d z = -fx x / z^2.
  EXPECT_NEAR(d_point(0, 0), 700.0 / 100.0, 1e-12);
  EXPECT_NEAR(d_point(0, 1), 0.0, 1e-12);
  EXPECT_NEAR(d_point(0, 2), -700.0 * 3.0 / 1e4, 1e-12);
  EXPECT_NEAR(d_point(1, 1), 650.0 / 100.0, 1e-12);
  EXPECT_NEAR(d_point(1, 2), 650.0 * 2.0 / 1e4, 1e-12);
}

}  // namespace
}  // namespace nadir::vo
