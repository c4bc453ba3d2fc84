#include "nodes/vo_feature/map_range.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace nadir::vo {

std::optional<double> rangeToPlaneAlongRay(std::vector<Eigen::Vector3d> points,
                                           const Eigen::Vector3d& ray) {
  const Eigen::Vector3d unit_ray = ray.normalized();
  for (int pass = 0; pass < 2; ++pass) {
    if (points.size() < kMinPlanePoints) return std::nullopt;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& p : points) centroid += p;
    centroid /= static_cast<double>(points.size());
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (const Eigen::Vector3d& p : points) scatter += (p - centroid) * (p - centroid).transpose();
    // The normal is the direction of least spread (the eigenvalues ascend).
    const Eigen::Vector3d normal =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0);
    const double along = normal.dot(unit_ray);
    if (std::abs(along) < 0.2) return std::nullopt;
    if (pass == 1) {
      const double range = normal.dot(centroid) / along;
      if (!(range > 0.0)) return std::nullopt;
      return range;
    }
    std::vector<double> distance;
    distance.reserve(points.size());
    for (const Eigen::Vector3d& p : points) distance.push_back(std::abs(normal.dot(p - centroid)));
    std::vector<double> sorted = distance;
    std::nth_element(sorted.begin(),
                     sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    // 1.4826 MAD is a Gaussian's sigma; the floor keeps an exact plane's points.
    const double limit = std::max(3.0 * 1.4826 * sorted[sorted.size() / 2], 1e-6 * centroid.norm());
    std::vector<Eigen::Vector3d> kept;
    for (std::size_t i = 0; i < points.size(); ++i)
      if (distance[i] <= limit) kept.push_back(points[i]);
    points = std::move(kept);
  }
  return std::nullopt;
}

}  // namespace nadir::vo
