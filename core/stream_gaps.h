#pragma once
// Counts what a periodic stream lost on the way, from the messages' own times:
// a message that comes n periods after the one before means n - 1 were lost.
// The period is given (the rate the sender should keep) or learnt from the
// first intervals; a stream whose first intervals are not multiples of one
// period (commands, heartbeats of several nodes) is irregular and not counted.
// A jump forward is counted once the stream goes on after it: a message
// stamped ahead of its stream that the stream then does not follow (a foreign
// or corrupt message) is out of order, never a loss.

#include <cstdint>
#include <optional>
#include <vector>

namespace nadir::core {

class StreamGaps {
 public:
  // Intervals the period is learnt from, when no rate is given.
  static constexpr int kLearnIntervals = 16;

  // expected_rate_hz > 0: the stream's rate in its messages' time; 0: learnt.
  explicit StreamGaps(double expected_rate_hz = 0.0);

  // Sets the rate from now on; times kept while learning are counted with it.
  void expectRate(double rate_hz);
  void add(std::int64_t utime);

  std::int64_t received() const { return received_; }
  // Messages lost: the sum over intervals of round(interval / period) - 1.
  std::int64_t missing() const { return missing_; }
  // Places where one or more were lost.
  std::int64_t gaps() const { return gaps_; }
  // Messages at or before the time of the one before (repeats, a log looped or
  // seeked), more than an hour after it, or ahead of it where the stream then
  // went on from before (a time from elsewhere: a foreign or corrupt message);
  // none counts as a loss.
  std::int64_t outOfOrder() const { return out_of_order_; }
  // The period counted with: given or learnt; 0 while not known or when irregular.
  double rateHz() const;
  bool learnt() const { return !given_ && period_us_ > 0.0; }
  bool irregular() const { return irregular_; }

 private:
  void count(std::int64_t utime);
  void learn();

  bool given_ = false;
  double period_us_ = 0.0;
  bool irregular_ = false;
  std::vector<std::int64_t> first_times_;  // until the period is known
  std::optional<std::int64_t> last_utime_;
  std::optional<std::int64_t> ahead_utime_;  // a jump forward, until the stream goes on
  std::int64_t received_ = 0;
  std::int64_t missing_ = 0;
  std::int64_t gaps_ = 0;
  std::int64_t out_of_order_ = 0;
};

}  // namespace nadir::core
