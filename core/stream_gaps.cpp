#include "core/stream_gaps.h"

#include <algorithm>
#include <cmath>

namespace nadir::core {
namespace {

// An interval within this share of a period of a whole number of periods is
// on the stream's beat (a camera's frames fall on sim steps: 30 or 32.5 ms
// for a 32.3 ms period).
constexpr double kBeatTolerance = 0.25;
// A step back by more than this many periods is a new start (a log looped or
// seeked), counted from there; a smaller one is a message out of order.
constexpr double kRestartPeriods = 2.0;

}  // namespace

StreamGaps::StreamGaps(double expected_rate_hz) {
  if (expected_rate_hz > 0.0) expectRate(expected_rate_hz);
}

void StreamGaps::expectRate(double rate_hz) {
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz)) return;
  given_ = true;
  irregular_ = false;
  period_us_ = 1e6 / rate_hz;
  std::vector<std::int64_t> kept;
  kept.swap(first_times_);
  for (const std::int64_t utime : kept) count(utime);
}

double StreamGaps::rateHz() const { return period_us_ > 0.0 ? 1e6 / period_us_ : 0.0; }

void StreamGaps::add(std::int64_t utime) {
  ++received_;
  if (period_us_ > 0.0 || irregular_) {
    count(utime);
    return;
  }
  first_times_.push_back(utime);
  if (static_cast<int>(first_times_.size()) > kLearnIntervals) learn();
}

void StreamGaps::count(std::int64_t utime) {
  if (last_utime_ && utime <= *last_utime_) {
    ++out_of_order_;
    if (period_us_ > 0.0 &&
        static_cast<double>(*last_utime_ - utime) > kRestartPeriods * period_us_) {
      last_utime_ = utime;
    }
    return;
  }
  if (last_utime_ && period_us_ > 0.0) {
    const double periods = static_cast<double>(utime - *last_utime_) / period_us_;
    const auto lost = static_cast<std::int64_t>(std::llround(periods)) - 1;
    if (lost > 0) {
      missing_ += lost;
      ++gaps_;
    }
  }
  last_utime_ = utime;
}

void StreamGaps::learn() {
  std::vector<double> intervals;
  for (std::size_t i = 1; i < first_times_.size(); ++i) {
    const std::int64_t interval = first_times_[i] - first_times_[i - 1];
    if (interval > 0) intervals.push_back(static_cast<double>(interval));
  }
  std::vector<double> sorted = intervals;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2),
                   sorted.end());
  const double median = sorted.empty() ? 0.0 : sorted[sorted.size() / 2];
  int on_beat = 0;
  for (const double interval : intervals) {
    const double periods = interval / median;
    if (std::abs(periods - std::round(periods)) <= kBeatTolerance) ++on_beat;
  }
  // Two intervals off the beat are allowed: a clock step, a message late.
  if (median > 0.0 && on_beat >= kLearnIntervals - 2) {
    period_us_ = median;
  } else {
    irregular_ = true;
  }
  std::vector<std::int64_t> kept;
  kept.swap(first_times_);
  for (const std::int64_t utime : kept) count(utime);
}

}  // namespace nadir::core
