#pragma once
// The one stamped-pose trajectory type: the body's pose in the world frame
// (local NED, body FRD) at times in seconds, its interpolation, and the files
// that hold one: TUM ("t tx ty tz qx qy qz qw", Hamilton) and flight CSV.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/axes.h"

namespace nadir::core {

class LocalNedFrame;

// A trajectory file that cannot be read or a trajectory that breaks its rules:
// the message names the file (and line) and says what is wrong, in one line.
class TrajectoryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct StampedPose {
  double t_s = 0;
  Eigen::Vector3d p_ned_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();
};

// Sorted by time wherever a function below says so.
using Trajectory = std::vector<StampedPose>;

// A message's utime as a trajectory stamp, s. The division is correctly rounded,
// so the stamp written to a TUM file reads back as the message's time.
inline double stampFromUtime(std::int64_t utime) { return static_cast<double>(utime) / 1e6; }

// Where t_s falls in a time-sorted trajectory: the samples before and after it
// and the fraction of the way from one to the other (i0 == i1 at a sample's
// own stamp). Nothing outside [front().t_s, back().t_s], or where the two
// samples are more than max_gap_s apart.
struct Bracket {
  std::size_t i0 = 0;
  std::size_t i1 = 0;
  double fraction = 0;
};
std::optional<Bracket> bracket(const Trajectory& trajectory, double t_s,
                               double max_gap_s = std::numeric_limits<double>::infinity());

// The pose at t_s: position linear, attitude SLERP (normalised) between the
// bracketing samples; under bracket()'s conditions.
std::optional<StampedPose> interpolate(const Trajectory& trajectory, double t_s,
                                       double max_gap_s = std::numeric_limits<double>::infinity());

// Sum of the distances between consecutive positions (the discrete arc length).
double trackLength(const Trajectory& trajectory);

// Throws TrajectoryError naming `source` unless the trajectory has at least
// min_poses poses with strictly increasing times.
void requireIncreasing(const Trajectory& trajectory, const std::string& source,
                       std::size_t min_poses);

// A TUM file: fields separated by spaces, tabs or commas; blank lines and
// lines starting with '#' skipped. Quaternions are normalised (a zero one is an
// error); times must increase strictly; at least one pose. A "# frame: world=enu
// body=flu" line (writeTum's) says the file's axes: its poses come back in
// nadir's (core/axes.h); without one they are taken as nadir's.
Trajectory readTum(const std::string& path);

// "t tx ty tz qx qy qz qw" lines in the shortest text that reads back to the
// same doubles, in the given axes (the trajectory is in nadir's), after a
// header that says them in a frame line.
void writeTum(const std::string& path, const Trajectory& trajectory, Axes axes = Axes::kNed,
              BodyAxes body = BodyAxes::kVehicle);

// A flight CSV: a header naming at least time_s, lat_deg, lon_deg, alt_m
// (ellipsoid), roll_deg, pitch_deg, yaw_deg (Z-Y-X), in any order, extra
// columns ignored; positions converted into `frame`.
Trajectory readFlightCsv(const std::string& path, const LocalNedFrame& frame);

}  // namespace nadir::core
