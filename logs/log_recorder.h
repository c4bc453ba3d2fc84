#pragma once
// Records what arrives on a bus into an LCM log, as lcm-logger does (each
// event stamped with its receive time), and counts per channel what was lost
// on the way, from the messages' own times and the rate each should keep
// (given, or learnt: core/stream_gaps.h). Unlike lcm-logger, whose one
// subscription keeps LCM's default queue of 30 messages, it queues the bus's
// queue_capacity: a burst while it waits for the CPU is not dropped.

#include <cstdint>
#include <map>
#include <string>

#include "core/bus.h"
#include "core/lcm_log.h"
#include "logs/channel_filter.h"

namespace nadir::logs {

struct RecorderOptions {
  // Record only channels whose whole name matches this POSIX extended regex; empty: all.
  std::string channels{};
  // Rates the senders keep (Hz of message time), for counting what was lost;
  // other channels have theirs learnt.
  std::map<std::string, double> expected_rates_hz{};
  // The live nodes' heartbeats (wall-clock times, several senders): recorded,
  // but no stream to count losses on, and no sign of data still coming.
  std::string heartbeat_channel = core::BusParams{}.heartbeat_channel;
};

class LogRecorder {
 public:
  // Creates path (throws core::LogError naming it) and subscribes to bus,
  // which must outlive the recorder.
  LogRecorder(core::Bus& bus, const std::string& path, RecorderOptions options = {});

  std::int64_t eventsWritten() const { return writer_.eventsWritten(); }
  std::int64_t bytesWritten() const { return bytes_; }
  // The wall time of the last message recorded, heartbeats and LCM's self
  // test aside (0 before the first).
  std::int64_t lastReceiveUtime() const { return last_receive_utime_; }
  // What arrived by channel, with what was lost (the bus's counters, of the
  // recorded channels only, heartbeats aside).
  std::map<std::string, core::ChannelStats> arrivals() const;
  void flush() { writer_.flush(); }

 private:
  core::Bus& bus_;
  ChannelFilter filter_;
  std::string heartbeat_channel_;
  core::LcmLogWriter writer_;
  std::int64_t bytes_ = 0;
  std::int64_t last_receive_utime_ = 0;
  core::Subscription subscription_;
};

}  // namespace nadir::logs
