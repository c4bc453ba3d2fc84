#include "dataset/trajectory.h"

#include <algorithm>

namespace nadir::dataset {
namespace {

Eigen::Isometry3d toIsometry(const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = p;
  return T;
}

}  // namespace

std::optional<Eigen::Isometry3d> interpolatePose(const std::vector<TruthSample>& samples,
                                                 std::int64_t utime, std::int64_t max_gap_us) {
  const auto after =
      std::lower_bound(samples.begin(), samples.end(), utime,
                       [](const TruthSample& sample, std::int64_t t) { return sample.utime < t; });
  if (after == samples.end()) return std::nullopt;
  if (after->utime == utime) return toIsometry(after->p_body_in_world_m, after->q_world_body);
  if (after == samples.begin()) return std::nullopt;
  const TruthSample& a = *(after - 1);
  const TruthSample& b = *after;
  if (b.utime - a.utime > max_gap_us) return std::nullopt;
  const double s = static_cast<double>(utime - a.utime) / static_cast<double>(b.utime - a.utime);
  const Eigen::Vector3d p = (1.0 - s) * a.p_body_in_world_m + s * b.p_body_in_world_m;
  // Eigen's slerp takes the shorter arc whatever the signs of the two quaternions.
  const Eigen::Quaterniond q = a.q_world_body.slerp(s, b.q_world_body);
  return toIsometry(p, q);
}

}  // namespace nadir::dataset
