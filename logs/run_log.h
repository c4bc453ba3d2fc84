#pragma once
// A run's trajectories as they were recorded or are being received: the truth
// (pose_t) and every VO source's estimates (vo_estimate_t), stamped with the
// messages' utime. Estimates are found by their type on whatever channel they
// come, and named by their `source` field (the node's registry name), so a
// renamed channel is never missed; so are a navigation filter's states
// (nav_state_t). The truth is pose_t on the channel given,
// or, when none is given, on the one channel of the log that carries pose_t.

#include <cstddef>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "core/lcm_log.h"
#include "core/trajectory.h"

namespace nadir::logs {

// A log that cannot be read as a run: the message names the file.
class RunLogError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One estimate of a source as it arrived. The pose means something only when
// TRACKING; status is vo_estimate_t's.
struct SourceEstimate : core::StampedPose {
  static constexpr int kInitializing = 0;
  static constexpr int kTracking = 1;
  static constexpr int kLost = 2;
  int status = kInitializing;
  int resets = 0;  // the node's num_resets so far
};

// One fused state of a navigation filter (nav_state_t) with the uncertainty
// the evaluation checks it against.
struct FilterState {
  double t_s = 0.0;
  Eigen::Vector3d p_ned_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();
  Eigen::Matrix3d position_covariance_m2 = Eigen::Matrix3d::Zero();
  // Body-frame small angle: R_true = R_estimate Exp(dtheta).
  Eigen::Matrix3d attitude_covariance_rad2 = Eigen::Matrix3d::Zero();
  // The last GPS fix the filter fused, s; NaN before the first.
  double last_gps_t_s = std::numeric_limits<double>::quiet_NaN();
};

// A waypoint the vehicle's guidance took as reached (waypoint_reached_t).
struct WaypointPassage {
  double t_s = 0.0;
  int index = 0;
  int count = 0;
  Eigen::Vector3d waypoint_ned_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d believed_ned_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d true_ned_m = Eigen::Vector3d::Zero();
  std::string source;  // what the guidance flew on
};

struct LogTrajectories {
  core::Trajectory truth;  // sorted by stamp, one pose per stamp
  std::string truth_channel;
  std::map<std::string, std::vector<SourceEstimate>> sources;  // by source name, sorted
  std::map<std::string, std::vector<FilterState>> filters;     // by source name, sorted
  std::vector<WaypointPassage> waypoints;                      // in time order
  std::string damage;  // the reader's damage report and what was left out; empty if clean
};

// Gathers the truth and the estimates one message at a time: from the events
// of a log (readRunLog) or from a live bus (the viewers' live mode).
class TrajectoryCollector {
 public:
  // truth_channel: where the truth's pose_t is; empty: the channel carrying pose_t.
  explicit TrajectoryCollector(std::string truth_channel = {});
  // Takes one message; false if it is neither truth, an estimate, a filter
  // state nor a waypoint reached. A message of these types that does not decode, or holds a
  // non-finite position or a quaternion that is not a rotation, is counted and left out.
  bool add(const std::string& channel, const void* data, std::size_t size);
  std::size_t truthPoses() const;
  // What was gathered so far. Throws RunLogError when pose_t came on several
  // channels and none was named the truth's.
  LogTrajectories trajectories() const;

 private:
  std::string truth_channel_;
  std::map<std::string, core::Trajectory> poses_;  // pose_t by channel
  std::vector<WaypointPassage> waypoints_;
  std::map<std::string, std::vector<SourceEstimate>> sources_;
  std::map<std::string, std::vector<FilterState>> filters_;
  std::map<std::string, std::size_t> undecodable_;  // channel -> count
};

// Reads a log's truth and estimates. A damaged log gives what could be read and
// says what was wrong in `damage`. Throws RunLogError naming the log if it
// cannot be opened, is empty, or holds no valid truth.
// progress is told how far the reading has come.
LogTrajectories readRunLog(const std::string& log_path, const std::string& truth_channel = {},
                           const core::ReadProgress& progress = {});

// The TRACKING estimates as a trajectory, normalised, the first of equal stamps kept.
core::Trajectory trackingTrajectory(const std::vector<SourceEstimate>& estimates);

// "a; b" joining of notes, for damage reports.
void appendNote(std::string& notes, const std::string& note);

}  // namespace nadir::logs
