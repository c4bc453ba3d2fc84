#pragma once
// A synthetic downward camera for VO tests: a multi-scale random texture on
// the level ground plane (world z = 0, NED), rendered into a frame with the
// exact homography of a camera pose. Independent of nadir's renderer, so that
// a VO's estimate can be compared with poses the test chose.

#include <cmath>

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

namespace nadir::test {

struct TexturedPlane {
  double metres_per_texel = 0.2;
  int texels = 4000;  // a square texture centred on the world origin
  // Intensities the texture spans (room left for gain changes).
  double lowest = 0.0;
  double highest = 255.0;
  unsigned seed = 12345;

  // Noise at four scales, blurred, equalised, fixed seed.
  cv::Mat texture() const {
    cv::RNG rng(seed);
    cv::Mat sum = cv::Mat::zeros(texels, texels, CV_32F);
    for (int k = 0; k < 4; ++k) {
      const int size = texels >> k;
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
    out.convertTo(out, CV_8U, (highest - lowest) / 255.0, lowest);
    return out;
  }

  // The frame a pinhole camera K at T_world_cam (camera: z forward) sees;
  // texel (u, v) is the ground point north = half - res v, east = -half + res u.
  cv::Mat render(const cv::Mat& texture, const Eigen::Isometry3d& T_world_cam, const cv::Matx33d& K,
                 cv::Size size) const {
    const double half = 0.5 * texels * metres_per_texel;
    Eigen::Matrix3d A;
    A << 0, -metres_per_texel, half, metres_per_texel, 0, -half, 0, 0, 0;
    Eigen::Matrix3d M = A;
    M.col(2) -= T_world_cam.translation();
    Eigen::Matrix3d Ke;
    Ke << K(0, 0), 0, K(0, 2), 0, K(1, 1), K(1, 2), 0, 0, 1;
    const Eigen::Matrix3d H = Ke * T_world_cam.linear().transpose() * M;
    cv::Matx33d H_cv;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) H_cv(r, c) = H(r, c);
    cv::Mat frame;
    cv::warpPerspective(texture, frame, H_cv, size, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                        cv::Scalar(0));
    return frame;
  }
};

// T_world_body from NED position and ZYX Euler angles (rad).
inline Eigen::Isometry3d bodyPose(const Eigen::Vector3d& p_ned_m, double roll, double pitch,
                                  double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                   .matrix();
  T.translation() = p_ned_m;
  return T;
}

}  // namespace nadir::test
