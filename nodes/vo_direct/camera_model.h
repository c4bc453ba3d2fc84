#pragma once
// The pinhole camera at each pyramid level, the pixel pattern a photometric
// residual is taken over, and the robust weight: the small pieces both the
// frame tracker and the window optimiser use.

#include <array>
#include <cmath>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace nadir::vo {

// The pyramid keeps every second pixel: x_l = x_0 / 2^l.
struct PinholeLevel {
  float fx = 1, fy = 1, cx = 0, cy = 0;

  static PinholeLevel at(const cv::Matx33d& K, int level) {
    const float s = 1.f / static_cast<float>(1 << level);
    return {static_cast<float>(K(0, 0)) * s, static_cast<float>(K(1, 1)) * s,
            static_cast<float>(K(0, 2)) * s, static_cast<float>(K(1, 2)) * s};
  }
  // The ray through pixel (x, y) with z = 1.
  Eigen::Vector3f ray(float x, float y) const { return {(x - cx) / fx, (y - cy) / fy, 1.f}; }
};

// The residual pattern around a point (DSO's eight pixels: a diamond of radius 2
// with the centre), in pixels of the level it is used at.
inline constexpr int kPatternSize = 8;
inline constexpr std::array<std::array<int, 2>, kPatternSize> kPattern = {
    {{0, -2}, {-1, -1}, {1, -1}, {-2, 0}, {0, 0}, {2, 0}, {-1, 1}, {0, 2}}};
inline constexpr int kPatternRadius = 2;

// The pattern's rays less the centre's (z = 0), turned by R: a pattern pixel of
// a point whose centre ray is c lies on the ray c + offset, so that a point at
// inverse depth rho maps to R c + rho t + (R offset), one rotation per pattern
// pixel for all points instead of one per point.
using PatternOffsets = std::array<Eigen::Vector3f, kPatternSize>;
inline PatternOffsets rotatedPatternOffsets(const PinholeLevel& camera, const Eigen::Matrix3f& R) {
  PatternOffsets out;
  for (int k = 0; k < kPatternSize; ++k)
    out[k] = R * Eigen::Vector3f(static_cast<float>(kPattern[k][0]) / camera.fx,
                                 static_cast<float>(kPattern[k][1]) / camera.fy, 0.f);
  return out;
}

// A point's pattern seen from another camera: qc is its centre ray turned
// and moved there (R c + rho t), offsets the turned pattern. Fills the pixels
// and says whether every one lies in front of the camera and inside
// [margin, x_max) x [margin, y_max); u and v are filled up to the first that does not.
inline bool projectPattern(const Eigen::Vector3f& qc, const PatternOffsets& offsets,
                           const PinholeLevel& camera, float margin, float x_max, float y_max,
                           std::array<float, kPatternSize>& u, std::array<float, kPatternSize>& v) {
  if (qc.z() <= 1e-6f) return false;
  for (int i = 0; i < kPatternSize; ++i) {
    const Eigen::Vector3f q = qc + offsets[i];
    if (q.z() <= 1e-6f) return false;
    const float iz = 1.f / q.z();
    u[i] = camera.fx * q.x() * iz + camera.cx;
    v[i] = camera.fy * q.y() * iz + camera.cy;
    if (!(u[i] >= margin && v[i] >= margin && u[i] < x_max && v[i] < y_max)) return false;
  }
  return true;
}

// The weight of a pixel by the reference's gradient there, c^2 / (c^2 +
// |grad|^2): on strong edges a small misalignment or blur makes large
// residuals. Taken from the reference (key-frame, host), not from the image
// being aligned, so that it does not change with the pose: the energy and its
// gradient then agree, and the steps descend.
inline float gradientWeight(float dx, float dy, float c2) { return c2 / (c2 + dx * dx + dy * dy); }

// Huber's weight for a residual r with threshold k: 1 inside, k/|r| beyond.
inline float huberWeight(float r, float k) {
  const float a = std::fabs(r);
  return a <= k ? 1.f : k / a;
}
// Huber's cost with the same threshold (r^2 inside, 2k|r| - k^2 beyond).
inline float huberCost(float r, float k) {
  const float a = std::fabs(r);
  return a <= k ? r * r : k * (2.f * a - k);
}

// The projection's derivative with respect to a left increment of the camera
// that sees the point, (translation, rotation), for a point at q / rho (q is the
// point scaled by its inverse depth rho, so far points stay finite), and with
// respect to rho: du/dxi = [rho * P(q), -P(q) [q]x], du/drho = P(q) t.
struct ProjectionJacobian {
  Eigen::Matrix<float, 2, 6> d_xi;
  Eigen::Vector2f d_rho;
};
inline ProjectionJacobian projectionJacobian(const Eigen::Vector3f& q, float rho,
                                             const Eigen::Vector3f& t, float fx, float fy) {
  const float iz = 1.f / q.z();
  const float x = q.x() * iz, y = q.y() * iz;
  // P(q) = [fx/qz, 0, -fx qx/qz^2; 0, fy/qz, -fy qy/qz^2]
  Eigen::Matrix<float, 2, 3> P;
  P << fx * iz, 0.f, -fx * x * iz, 0.f, fy * iz, -fy * y * iz;
  Eigen::Matrix3f q_cross;
  q_cross << 0.f, -q.z(), q.y(), q.z(), 0.f, -q.x(), -q.y(), q.x(), 0.f;
  ProjectionJacobian J;
  J.d_xi.leftCols<3>() = rho * P;
  J.d_xi.rightCols<3>() = -P * q_cross;
  J.d_rho = P * t;
  return J;
}

}  // namespace nadir::vo
