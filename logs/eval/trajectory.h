#pragma once
// Stamped pose trajectories for evaluation: the TUM text format, interpolation
// of a reference at other times, and timestamp association (as evo does it).
//
// Every pose is T_world_body in the world frame (local NED in nadir), with the
// time in seconds. TUM lines are "t tx ty tz qx qy qz qw" (Hamilton, x y z w).

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstddef>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace nadir::eval {

// Any evaluation error: a missing or malformed file, too few poses to compare.
// The message names the file (and line) and says what is wrong, in one line.
class EvalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct StampedPose {
  double t_s = 0;
  Eigen::Vector3d p_m = Eigen::Vector3d::Zero();          // position, world NED
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();  // R_world_body
};
using PoseTrajectory = std::vector<StampedPose>;

// Reads a TUM trajectory: one pose per line, fields separated by spaces, tabs or
// commas; blank lines and lines starting with '#' are skipped. Quaternions are
// normalised (a zero one is an error); timestamps must increase strictly.
// Throws EvalError "PATH:LINE: what is wrong" (or "PATH: ..." for the file).
PoseTrajectory readTum(const std::string& path);

// Writes "t tx ty tz qx qy qz qw" lines with the shortest text that reads back
// to the same doubles. Throws EvalError naming the path if it cannot write.
void writeTum(const std::string& path, const PoseTrajectory& trajectory);

// The pose of a time-sorted trajectory at t_s: position linear, attitude SLERP
// between the two samples around t_s. Nothing if t_s is outside
// [front().t_s, back().t_s], or if those two samples are more than max_gap_s apart.
std::optional<StampedPose> interpolate(const PoseTrajectory& trajectory, double t_s,
                                       double max_gap_s = std::numeric_limits<double>::infinity());

// Index pairs (ref, est) of poses with matching stamps, as evo's
// sync.associate_trajectories (nearest stamp within t_max_diff_s), made one to
// one: a pair is kept when each stamp is the other's nearest and they differ by
// at most t_max_diff_s. Both inputs sorted by time; pairs come in time order.
std::vector<std::pair<std::size_t, std::size_t>> associate(const PoseTrajectory& ref,
                                                           const PoseTrajectory& est,
                                                           double t_max_diff_s);

// Sum of the distances between consecutive positions (the discrete arc length).
double trackLength(const PoseTrajectory& trajectory);

}  // namespace nadir::eval
