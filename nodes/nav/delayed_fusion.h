#pragma once
// The filter in message time. A VO's estimate of a frame comes after the IMU
// samples that followed the frame (the VO takes time), so the filter runs a
// fixed delay behind the newest IMU sample: every sample and measurement is
// queued and fused in time order once the horizon passes it, and the present
// estimate is the delayed one carried forward with the IMU samples since (the
// nominal state only; the covariance given is the delayed one). PX4's EKF2
// works on a delayed horizon the same way.

#include <cstdint>
#include <functional>
#include <map>

#include "nodes/nav/error_state_filter.h"

namespace nadir::nav {

class DelayedFusion {
 public:
  // An update applied to the filter when its time comes.
  using Update = std::function<void(ErrorStateFilter&)>;

  // Throws std::invalid_argument for a negative delay.
  DelayedFusion(ErrorStateFilter filter, double delay_s);

  // IMU samples in their order; each moves the horizon to its time less the
  // delay and fuses what the horizon passed.
  void addImu(const ImuSample& imu);
  // A measurement stamped utime. One older than the horizon is refused
  // (counted by late()); measurements of equal stamps are fused in the order
  // they came. A measurement is fused at its own time: the interval between
  // the IMU samples around it is split there (the later sample's readings
  // over both parts); with no later sample yet, at the last one before it.
  bool addMeasurement(std::int64_t utime, Update update);

  // The delayed filter, and the present estimate carried forward from it.
  const ErrorStateFilter& delayed() const { return filter_; }
  NavState present() const;
  std::int64_t horizonUtime() const { return horizon_utime_; }
  std::int64_t late() const { return late_; }

 private:
  struct Event {
    bool is_imu = false;
    ImuSample imu;
    Update update;
  };
  void release();

  ErrorStateFilter filter_;
  std::int64_t delay_us_;
  std::int64_t horizon_utime_ = INT64_MIN;
  std::multimap<std::int64_t, Event> queue_;
  std::int64_t late_ = 0;
};

}  // namespace nadir::nav
