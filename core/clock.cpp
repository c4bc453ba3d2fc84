#include "core/clock.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace nadir::core {

bool due(std::int64_t utime, double rate_hz, std::int64_t& next_due_utime) {
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz)) {
    throw std::invalid_argument("due: rate_hz must be positive and finite");
  }
  const std::int64_t period_us = std::max<std::int64_t>(1, std::llround(1e6 / rate_hz));
  if (next_due_utime == kDueAtFirstCall) {
    next_due_utime = utime + period_us;
    return true;
  }
  if (utime < next_due_utime) return false;
  // The first grid point strictly after utime.
  const std::int64_t steps = (utime - next_due_utime) / period_us + 1;
  next_due_utime += steps * period_us;
  return true;
}

}  // namespace nadir::core
