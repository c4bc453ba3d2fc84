#include "nodes/common/flight_inputs.h"

#include <algorithm>
#include <iterator>

#include "lcmtypes/bus_io.h"

namespace nadir::nodes {
namespace {

// Enough for a 200 Hz attitude stream to cover the frames a slow node is behind.
constexpr std::size_t kAttitudeHistory = 64;
// The same for a 50 Hz rangefinder.
constexpr std::size_t kRangeHistory = 32;

}  // namespace

FlightInputs::FlightInputs(core::Bus& bus, const std::string& range_channel,
                           const std::string& attitude_channel) {
  subscriptions_.push_back(
      msg::subscribe<msg::Range>(bus, range_channel, [this](const msg::Range& range) {
        ranges_.push_back(range);
        if (ranges_.size() > kRangeHistory) ranges_.pop_front();
      }));
  subscriptions_.push_back(
      msg::subscribe<msg::Attitude>(bus, attitude_channel, [this](const msg::Attitude& attitude) {
        attitudes_.push_back(attitude);
        if (attitudes_.size() > kAttitudeHistory) attitudes_.pop_front();
      }));
}

std::optional<double> FlightInputs::rangeAt_m(std::int64_t utime) const {
  const auto valid = [](const msg::Range& r) { return r.status == msg::RangeStatus::VALID; };
  const auto after = std::find_if(ranges_.begin(), ranges_.end(),
                                  [utime](const msg::Range& r) { return r.utime > utime; });
  if (after == ranges_.begin()) return std::nullopt;
  const msg::Range& before = *std::prev(after);
  if (!valid(before)) return std::nullopt;
  if (after == ranges_.end()) return before.range_m;
  if (!valid(*after)) return std::nullopt;
  const double s =
      static_cast<double>(utime - before.utime) / static_cast<double>(after->utime - before.utime);
  return before.range_m + s * (after->range_m - before.range_m);
}

std::optional<Eigen::Quaterniond> FlightInputs::attitudeAt(std::int64_t utime) const {
  for (auto it = attitudes_.rbegin(); it != attitudes_.rend(); ++it) {
    if (it->utime <= utime) return it->q_world_body;
  }
  return std::nullopt;
}

}  // namespace nadir::nodes
