#pragma once
// What VO nodes read from the flight stack besides images, kept current from
// the bus: short histories of the rangefinder's readings and of the flight
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

  // The range at utime, m: interpolated between the readings just before and
  // just after it when both are VALID, else the one at or before it when that
  // is the latest and VALID; nothing otherwise. An image is stamped at its
  // exposure and arrives after later readings: in a banked turn the slant
  // range changes by metres between two of them.
  std::optional<double> rangeAt_m(std::int64_t utime) const;
  // The attitude at or just before utime (R_world_body); nothing if none is that old.
  std::optional<Eigen::Quaterniond> attitudeAt(std::int64_t utime) const;

 private:
  std::deque<msg::Range> ranges_;
  std::deque<msg::Attitude> attitudes_;
  std::vector<core::Subscription> subscriptions_;
};

}  // namespace nadir::nodes
