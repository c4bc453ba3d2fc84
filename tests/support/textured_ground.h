#pragma once
// A flat ground of random texture 150 m below a downward camera, rendered with
// the exact homography of the camera's pose: frames for the feature VO whose
// truth is known exactly.

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace nadir::test {

constexpr double kGroundTextureResM = 0.2;  // ground metres per texture pixel
constexpr int kGroundTextureSize = 4000;    // covers +-400 m north and east
constexpr double kGroundTextureHalfM = 400.0;

// Multi-scale random texture: noise at four scales, fixed seed.
inline const cv::Mat& groundTexture() {
  static const cv::Mat texture = [] {
    cv::RNG rng(12345);
    cv::Mat sum = cv::Mat::zeros(kGroundTextureSize, kGroundTextureSize, CV_32F);
    for (int k = 0; k < 4; ++k) {
      const int size = kGroundTextureSize >> k;
      cv::Mat noise(size, size, CV_32F);
      rng.fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
      cv::Mat up;
      cv::resize(noise, up, sum.size(), 0, 0, cv::INTER_CUBIC);
      sum += up;
    }
    cv::GaussianBlur(sum, sum, cv::Size(0, 0), 1.0);
    cv::Mat out;
    cv::normalize(sum, sum, 0, 255, cv::NORM_MINMAX);
    sum.convertTo(out, CV_8U);
    cv::equalizeHist(out, out);
    return out;
  }();
  return texture;
}

// T_world_body from a position and Z-Y-X angles, rad.
inline Eigen::Isometry3d bodyPose(const Eigen::Vector3d& p, double roll, double pitch, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                   .matrix();
  T.translation() = p;
  return T;
}

// The frame a camera with intrinsics K at T_world_cam sees: texture pixel (u, v)
// is the ground point north = 400 - 0.2 v, east = -400 + 0.2 u, down = 0.
inline cv::Mat renderGround(const Eigen::Isometry3d& T_world_cam, const cv::Matx33d& K_cv,
                            cv::Size size) {
  Eigen::Matrix3d A;
  A << 0, -kGroundTextureResM, kGroundTextureHalfM, kGroundTextureResM, 0, -kGroundTextureHalfM, 0,
      0, 0;
  const Eigen::Matrix3d R_cw = T_world_cam.linear().transpose();
  Eigen::Matrix3d M = A;
  M.col(2) -= T_world_cam.translation();
  Eigen::Matrix3d K;
  K << K_cv(0, 0), 0, K_cv(0, 2), 0, K_cv(1, 1), K_cv(1, 2), 0, 0, 1;
  const Eigen::Matrix3d H = K * R_cw * M;
  cv::Matx33d H_cv;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) H_cv(r, c) = H(r, c);
  cv::Mat frame;
  cv::warpPerspective(groundTexture(), frame, H_cv, size, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                      cv::Scalar(0));
  return frame;
}

}  // namespace nadir::test
