#include "nodes/vo_feature/map_range.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace nadir::vo {

namespace {

// Below this |normal . ray| the plane is seen too nearly edge-on for a range.
constexpr double kMinNormalAlongRay = 0.2;

struct Plane {
  Eigen::Vector3d centroid;
  Eigen::Vector3d normal;
};

// Least squares: through the centroid, the normal the direction of least
// spread (the eigenvalues ascend).
Plane fitPlane(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) scatter += (p - centroid) * (p - centroid).transpose();
  return {centroid, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0)};
}

}  // namespace

std::optional<double> rangeToPlaneAlongRay(const std::vector<Eigen::Vector3d>& points,
                                           const Eigen::Vector3d& ray) {
  if (points.size() < kMinPlanePoints) return std::nullopt;
  const Eigen::Vector3d unit_ray = ray.normalized();
  const Plane first = fitPlane(points);
  if (std::abs(first.normal.dot(unit_ray)) < kMinNormalAlongRay) return std::nullopt;

  // Again without the points more than 3 robust sigmas off the first plane.
  std::vector<double> distance;
  distance.reserve(points.size());
  for (const Eigen::Vector3d& p : points)
    distance.push_back(std::abs(first.normal.dot(p - first.centroid)));
  std::vector<double> sorted = distance;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2),
                   sorted.end());
  // 1.4826 MAD is a Gaussian's sigma; the floor keeps an exact plane's points.
  const double limit =
      std::max(3.0 * 1.4826 * sorted[sorted.size() / 2], 1e-6 * first.centroid.norm());
  std::vector<Eigen::Vector3d> kept;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (distance[i] <= limit) kept.push_back(points[i]);
  if (kept.size() < kMinPlanePoints) return std::nullopt;

  const Plane plane = fitPlane(kept);
  const double along = plane.normal.dot(unit_ray);
  if (std::abs(along) < kMinNormalAlongRay) return std::nullopt;
  const double range = plane.normal.dot(plane.centroid) / along;
  if (!(range > 0.0)) return std::nullopt;
  return range;
}

double scaleCorrection(double ratio, double tolerance, double gain, double max_step) {
  if (!(ratio > 0.0) || std::abs(ratio - 1.0) <= tolerance) return 1.0;
  return std::clamp(1.0 + gain * (1.0 / ratio - 1.0), 1.0 - max_step, 1.0 + max_step);
}

}  // namespace nadir::vo
