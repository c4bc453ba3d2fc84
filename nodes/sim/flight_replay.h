#pragma once
// A recorded flight replayed as truth: the state at any time between its poses
// (position linear, attitude SLERP), so a real flight can drive the camera and
// the sensors.

#include <cstdint>
#include <string>

#include "core/trajectory.h"
#include "nodes/sim/vehicle_state.h"

namespace nadir::sim {

class FlightReplay {
 public:
  // Needs at least two poses with increasing times; throws core::TrajectoryError
  // naming `source` otherwise.
  FlightReplay(core::Trajectory flight, const std::string& source);

  std::int64_t startUtime() const { return start_utime_; }
  std::int64_t endUtime() const { return end_utime_; }

  // The state at utime (clamped to the recorded span): velocity and body rates
  // from the interval around it, acceleration from the neighbouring intervals.
  VehicleState at(std::int64_t utime) const;

 private:
  // Stamped in seconds after start_utime_: near the epoch, absolute seconds would
  // keep only a quarter of a microsecond.
  core::Trajectory flight_;
  std::int64_t start_utime_ = 0;
  std::int64_t end_utime_ = 0;
};

}  // namespace nadir::sim
