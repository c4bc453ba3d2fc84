#include "logs/eval/trajectory.h"

#include <algorithm>
#include <cmath>

namespace nadir::eval {
namespace {

std::vector<double> stamps(const core::Trajectory& trajectory) {
  std::vector<double> t;
  t.reserve(trajectory.size());
  for (const core::StampedPose& pose : trajectory) t.push_back(pose.t_s);
  return t;
}

// Index of the stamp nearest to t in sorted stamps (the earlier one on a tie,
// as numpy's argmin); stamps must not be empty.
std::size_t nearestIndex(const std::vector<double>& sorted, double t) {
  const auto upper = std::lower_bound(sorted.begin(), sorted.end(), t);
  if (upper == sorted.begin()) return 0;
  if (upper == sorted.end()) return sorted.size() - 1;
  const auto lower = upper - 1;
  return static_cast<std::size_t>((t - *lower <= *upper - t ? lower : upper) - sorted.begin());
}

}  // namespace

std::vector<std::pair<std::size_t, std::size_t>> associate(const core::Trajectory& ref,
                                                           const core::Trajectory& est,
                                                           double t_max_diff_s) {
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  if (ref.empty() || est.empty()) return pairs;
  const std::vector<double> ref_t = stamps(ref);
  const std::vector<double> est_t = stamps(est);
  for (std::size_t i = 0; i < est_t.size(); ++i) {
    const std::size_t j = nearestIndex(ref_t, est_t[i]);
    if (std::abs(ref_t[j] - est_t[i]) > t_max_diff_s) continue;
    if (nearestIndex(est_t, ref_t[j]) != i) continue;
    pairs.emplace_back(j, i);
  }
  return pairs;
}

}  // namespace nadir::eval
