#include "nodes/nav/delayed_fusion.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <utility>

namespace nadir::nav {

DelayedFusion::DelayedFusion(ErrorStateFilter filter, double delay_s)
    : filter_(std::move(filter)), delay_us_(std::llround(delay_s * 1e6)) {
  if (!(delay_s >= 0.0) || !std::isfinite(delay_s))
    throw std::invalid_argument("the fusion's delay must be a time >= 0 s");
}

void DelayedFusion::addImu(const ImuSample& imu) {
  Event event;
  event.is_imu = true;
  event.imu = imu;
  queue_.emplace(imu.utime, std::move(event));
  horizon_utime_ = std::max(horizon_utime_, imu.utime - delay_us_);
  release();
}

bool DelayedFusion::addMeasurement(std::int64_t utime, Update update) {
  if (utime < horizon_utime_) {
    ++late_;
    return false;
  }
  Event event;
  event.update = std::move(update);
  // Past the IMU samples of the same stamp, so that it sees them.
  queue_.emplace_hint(queue_.upper_bound(utime), utime, std::move(event));
  return true;
}

void DelayedFusion::release() {
  while (!queue_.empty() && queue_.begin()->first <= horizon_utime_) {
    const auto it = queue_.begin();
    Event& event = it->second;
    if (event.is_imu) {
      filter_.propagate(event.imu);
    } else {
      if (filter_.hasTime() && it->first > filter_.state().utime) {
        // At its own time: the interval to the next sample is split there,
        // with that sample's readings over both parts.
        const auto next = std::find_if(std::next(it), queue_.end(),
                                       [](const auto& entry) { return entry.second.is_imu; });
        if (next != queue_.end()) {
          ImuSample split = next->second.imu;
          split.utime = it->first;
          filter_.propagate(split);
        }
      }
      event.update(filter_);
    }
    queue_.erase(it);
  }
}

NavState DelayedFusion::present() const {
  NavState state = filter_.state();
  bool has_time = filter_.hasTime();
  for (const auto& [utime, event] : queue_) {
    if (!event.is_imu) continue;
    if (!has_time) {
      // The first sample only sets the time, as in the filter.
      state.utime = utime;
      has_time = true;
      continue;
    }
    if (utime <= state.utime) continue;
    propagateNominal(state, event.imu, 1e-6 * static_cast<double>(utime - state.utime));
  }
  return state;
}

}  // namespace nadir::nav
