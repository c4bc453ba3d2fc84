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
// A step forward by more than this is no loss either but a time from elsewhere
// (a foreign or corrupt message, a clock set): a new start, like a step back.
constexpr double kMaxStep_us = 3600e6;

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
  if (!last_utime_) {
    last_utime_ = utime;
    return;
  }
  if (ahead_utime_) {
    // After a jump forward: a stream that goes on after it lost what the jump
    // spans; one that goes on from before it makes the jump a time from elsewhere.
    const std::int64_t ahead = *ahead_utime_;
    ahead_utime_.reset();
    if (utime > ahead) {
      const auto lost =
          static_cast<std::int64_t>(std::llround(
              (static_cast<double>(ahead) - static_cast<double>(*last_utime_)) / period_us_)) -
          1;
      missing_ += lost;
      ++gaps_;
      last_utime_ = ahead;
    } else {
      ++out_of_order_;
    }
  }
  // In double: the times of a foreign message are any 64 bits.
  const double step_us = static_cast<double>(utime) - static_cast<double>(*last_utime_);
  if (step_us <= 0.0) {
    ++out_of_order_;
    if (period_us_ > 0.0 && -step_us > kRestartPeriods * period_us_) last_utime_ = utime;
    return;
  }
  if (step_us > kMaxStep_us) {
    ++out_of_order_;
  } else if (period_us_ > 0.0 && std::llround(step_us / period_us_) > 1) {
    ahead_utime_ = utime;
    return;
  }
  last_utime_ = utime;
}

void StreamGaps::learn() {
  std::vector<double> intervals;
  for (std::size_t i = 1; i < first_times_.size(); ++i) {
    const double interval =
        static_cast<double>(first_times_[i]) - static_cast<double>(first_times_[i - 1]);
    if (interval > 0.0 && interval <= kMaxStep_us) intervals.push_back(interval);
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
