#pragma once
// What VO nodes read from the flight stack besides images, kept current from
// the bus: the latest rangefinder reading and a short history of the flight
// controller's attitude, looked up at an image's time.

#include <deque>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/bus.h"
#include "lcmtypes/messages.h"

namespace nadir::nodes {

class FlightInputs {
 public:
  FlightInputs(core::Bus& bus, const std::string& range_channel,
               const std::string& attitude_channel);

  // The latest VALID range, m; nothing before one or when the latest is not valid.
  std::optional<double> validRange_m() const;
  // The attitude at or just before utime (R_world_body); nothing if none is that old.
  std::optional<Eigen::Quaterniond> attitudeAt(std::int64_t utime) const;

 private:
  std::optional<msg::Range> range_;
  std::deque<msg::Attitude> attitudes_;
  std::vector<core::Subscription> subscriptions_;
};

}  // namespace nadir::nodes
