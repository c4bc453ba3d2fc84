#include "nodes/common/flight_inputs.h"

#include "lcmtypes/bus_io.h"

namespace nadir::nodes {
namespace {

// Enough for a 200 Hz attitude stream to cover the frames a slow node is behind.
constexpr std::size_t kAttitudeHistory = 64;

}  // namespace

FlightInputs::FlightInputs(core::Bus& bus, const std::string& range_channel,
                           const std::string& attitude_channel) {
  subscriptions_.push_back(msg::subscribe<msg::Range>(
      bus, range_channel, [this](const msg::Range& range) { range_ = range; }));
  subscriptions_.push_back(
      msg::subscribe<msg::Attitude>(bus, attitude_channel, [this](const msg::Attitude& attitude) {
        attitudes_.push_back(attitude);
        if (attitudes_.size() > kAttitudeHistory) attitudes_.pop_front();
      }));
}

std::optional<double> FlightInputs::validRange_m() const {
  if (!range_ || range_->status != msg::RangeStatus::VALID) return std::nullopt;
  return range_->range_m;
}

std::optional<Eigen::Quaterniond> FlightInputs::attitudeAt(std::int64_t utime) const {
  for (auto it = attitudes_.rbegin(); it != attitudes_.rend(); ++it) {
    if (it->utime <= utime) return it->q_world_body;
  }
  return std::nullopt;
}

}  // namespace nadir::nodes
