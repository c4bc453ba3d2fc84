#pragma once
// Time in nadir is int64 microseconds ("utime"). Live nodes stamp with the
// wall clock; batch runs and log replay use the time carried by the messages.

#include <chrono>
#include <cstdint>
#include <limits>

namespace nadir::core {

inline std::int64_t wallClockUtime() {
  using namespace std::chrono;
  return duration_cast<microseconds>(system_clock::now().time_since_epoch()).count();
}

constexpr double secondsFromUtime(std::int64_t utime) { return static_cast<double>(utime) * 1e-6; }
constexpr std::int64_t utimeFromSeconds(double t_s) {
  return static_cast<std::int64_t>(t_s * 1e6 + (t_s >= 0 ? 0.5 : -0.5));
}

// Initial value of a next_due_utime for due(): the first call is due.
inline constexpr std::int64_t kDueAtFirstCall = std::numeric_limits<std::int64_t>::min();

// Fixed-grid sampling in message time. The first call (next_due_utime ==
// kDueAtFirstCall) is due and anchors the grid at utime; after that a call is
// due when utime has reached next_due_utime, and due times advance on the grid
// anchor + k * period, period = 1e6 / rate_hz rounded to whole microseconds
// (at least 1). If utime skips grid points, one sample is due and the next due
// time is the first grid point after utime: the grid never drifts. Throws
// std::invalid_argument if rate_hz is not positive and finite.
bool due(std::int64_t utime, double rate_hz, std::int64_t& next_due_utime);

}  // namespace nadir::core
