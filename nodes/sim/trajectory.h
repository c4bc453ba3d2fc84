#pragma once
// A recorded trajectory as truth: poses at their times, read from a TUM file
// or a flight CSV, and the state at any time in between (linear position,
// SLERP attitude), so a real flight can drive the camera and sensors.

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/geodesy.h"
#include "nodes/sim/vehicle_state.h"

namespace nadir::sim {

class TrajectoryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct TrajectoryPose {
  std::int64_t utime = 0;
  Eigen::Vector3d p_ned_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();
};

class Trajectory {
 public:
  // Poses strictly increasing in time, at least two; throws TrajectoryError otherwise.
  explicit Trajectory(std::vector<TrajectoryPose> poses, std::string source = "trajectory");

  std::int64_t startUtime() const { return poses_.front().utime; }
  std::int64_t endUtime() const { return poses_.back().utime; }
  const std::vector<TrajectoryPose>& poses() const { return poses_; }

  // The state at utime (clamped to the recorded span): position linear and
  // attitude SLERP between the neighbouring poses; velocity and body rates
  // from that interval, acceleration from the neighbouring intervals.
  VehicleState at(std::int64_t utime) const;

 private:
  std::size_t intervalOf(std::int64_t utime) const;
  std::vector<TrajectoryPose> poses_;
  std::string source_;
};

// TUM format: "timestamp_s tx ty tz qx qy qz qw" per line, '#' comments; the
// positions are taken as world-frame NED metres and the quaternion as R_world_body.
Trajectory readTumTrajectory(const std::string& path);

// CSV with a header naming at least time_s, lat_deg, lon_deg, alt_m, roll_deg,
// pitch_deg, yaw_deg (any order, extra columns ignored); positions are
// converted to the world frame of `frame`.
Trajectory readFlightCsv(const std::string& path, const core::LocalNedFrame& frame);

}  // namespace nadir::sim
