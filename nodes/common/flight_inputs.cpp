#include "nodes/common/flight_inputs.h"

#include "core/frames.h"

namespace nadir::nodes {
namespace {

// Enough for a 200 Hz attitude stream to cover the frames a slow node is behind.
constexpr std::size_t kAttitudeHistory = 64;

}  // namespace

FlightInputs::FlightInputs(core::Bus& bus, const std::string& range_channel,
                           const std::string& attitude_channel) {
  subscriptions_.push_back(core::subscribe<nadir::range_t>(
      bus, range_channel, [this](const nadir::range_t& range) { range_ = range; }));
  subscriptions_.push_back(core::subscribe<nadir::attitude_t>(
      bus, attitude_channel, [this](const nadir::attitude_t& attitude) {
        attitudes_.push_back(attitude);
        if (attitudes_.size() > kAttitudeHistory) attitudes_.pop_front();
      }));
}

std::optional<double> FlightInputs::validRange_m() const {
  if (!range_ || range_->status != nadir::range_t::STATUS_VALID) return std::nullopt;
  return range_->range_m;
}

std::optional<Eigen::Quaterniond> FlightInputs::attitudeAt(std::int64_t utime) const {
  for (auto it = attitudes_.rbegin(); it != attitudes_.rend(); ++it) {
    if (it->utime <= utime) return core::quaternionFromWire(it->orientation);
  }
  return std::nullopt;
}

}  // namespace nadir::nodes
