#pragma once
// Ground truth as the exporter holds it, and its interpolation at image times.

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace nadir::dataset {

// One pose_t of the truth channel: T_world_body (world local NED, body FRD).
struct TruthSample {
  std::int64_t utime = 0;
  Eigen::Vector3d p_body_in_world_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();
  Eigen::Vector3d v_world_mps = Eigen::Vector3d::Zero();
};

// T_world_body at utime from samples sorted by strictly increasing utime: the
// sample itself at a sample's time, otherwise linear in position and SLERP in
// orientation between the two samples around utime. Nothing before the first
// or after the last sample, or when the two around it are more than
// max_gap_us apart (truth missing there, for example in a damaged log).
std::optional<Eigen::Isometry3d> interpolatePose(const std::vector<TruthSample>& samples,
                                                 std::int64_t utime, std::int64_t max_gap_us);

}  // namespace nadir::dataset
