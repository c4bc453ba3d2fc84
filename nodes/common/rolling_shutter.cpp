#include "nodes/common/rolling_shutter.h"

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <stdexcept>

namespace nadir::vo {
namespace {

// The map is worked out on a grid this coarse and interpolated: the warp is smooth.
constexpr int kGridPx = 16;

Eigen::Matrix3d rotationExp(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle < 1e-12) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

}  // namespace

CameraTwist cameraTwist(const Eigen::Isometry3d& T_prev_cur, double dt_s) {
  // T_world_cam(k) = T_world_cam(k-1) T_prev_cur: the rotation is Exp(omega dt)
  // and the translation v dt, in the previous frame's camera axes.
  const Eigen::AngleAxisd turn(T_prev_cur.linear());
  CameraTwist twist;
  twist.omega_cam_rps = turn.angle() * turn.axis() / dt_s;
  twist.v_cam_mps = T_prev_cur.translation() / dt_s;
  return twist;
}

cv::Mat rectifyRollingShutter(const cv::Mat& gray, const cv::Matx33d& K, double readout_s,
                              const CameraTwist& twist, double depth_m) {
  if (gray.empty() || gray.type() != CV_8UC1)
    throw std::invalid_argument("rectifyRollingShutter: needs an 8-bit gray image");
  if (!(depth_m > 0.0) || !std::isfinite(depth_m))
    throw std::invalid_argument("rectifyRollingShutter: depth_m must be positive");
  const double fx = K(0, 0), fy = K(1, 1), cx = K(0, 2), cy = K(1, 2);
  const int rows = gray.rows, cols = gray.cols;
  const double v_mid = 0.5 * (rows - 1);
  const int grid_cols = cols / kGridPx + 2, grid_rows = rows / kGridPx + 2;
  cv::Mat grid_x(grid_rows, grid_cols, CV_32F), grid_y(grid_rows, grid_cols, CV_32F);
  for (int gr = 0; gr < grid_rows; ++gr) {
    for (int gc = 0; gc < grid_cols; ++gc) {
      // The point a global shutter sees at pixel (u0, v0), at depth_m.
      const double u0 = gc * kGridPx, v0 = gr * kGridPx;
      const Eigen::Vector3d p0((u0 - cx) / fx * depth_m, (v0 - cy) / fy * depth_m, depth_m);
      // Where the rolling shutter saw it: at the time of the row it fell on,
      // from the pose then: p_t = Exp(-omega t) (p0 - v t). The row depends
      // on the time: three fixed-point steps from the global row.
      double u = u0, v = v0;
      for (int it = 0; it < 3; ++it) {
        const double t = (v - v_mid) / rows * readout_s;
        const Eigen::Vector3d p =
            rotationExp(-twist.omega_cam_rps * t) * (p0 - twist.v_cam_mps * t);
        if (p.z() <= 1e-6) break;
        u = fx * p.x() / p.z() + cx;
        v = fy * p.y() / p.z() + cy;
      }
      grid_x.at<float>(gr, gc) = static_cast<float>(u - u0);
      grid_y.at<float>(gr, gc) = static_cast<float>(v - v0);
    }
  }
  // Each pixel's shift, bilinear between the grid's nodes.
  cv::Mat map_x(rows, cols, CV_32F), map_y(rows, cols, CV_32F);
  for (int r = 0; r < rows; ++r) {
    const int gr = r / kGridPx;
    const float fr = static_cast<float>(r - gr * kGridPx) / kGridPx;
    float* mx = map_x.ptr<float>(r);
    float* my = map_y.ptr<float>(r);
    const float* x0 = grid_x.ptr<float>(gr);
    const float* x1 = grid_x.ptr<float>(gr + 1);
    const float* y0 = grid_y.ptr<float>(gr);
    const float* y1 = grid_y.ptr<float>(gr + 1);
    for (int c = 0; c < cols; ++c) {
      const int gc = c / kGridPx;
      const float fc = static_cast<float>(c - gc * kGridPx) / kGridPx;
      const auto lerp = [&](const float* g0, const float* g1) {
        const float top = (1 - fc) * g0[gc] + fc * g0[gc + 1];
        const float bottom = (1 - fc) * g1[gc] + fc * g1[gc + 1];
        return (1 - fr) * top + fr * bottom;
      };
      mx[c] = static_cast<float>(c) + lerp(x0, x1);
      my[c] = static_cast<float>(r) + lerp(y0, y1);
    }
  }
  cv::Mat out;
  cv::remap(gray, out, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return out;
}

}  // namespace nadir::vo
