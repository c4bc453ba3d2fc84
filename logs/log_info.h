#pragma once
// What is in an LCM log: per-channel counts, rates and gaps, the time spans
// (event timestamps and the messages' own utime) and any damage.

#include <cstdint>
#include <string>
#include <vector>

#include "core/lcm_log.h"
#include "logs/log_index.h"

namespace nadir::logs {

struct ChannelInfo {
  std::string channel;
  std::int64_t messages = 0;
  std::int64_t bytes = 0;        // payload bytes (without the event headers)
  std::int64_t first_utime = 0;  // event timestamps of the first and last message
  std::int64_t last_utime = 0;
  // Mean rate: (messages - 1) / (last - first); 0 with fewer than two
  // messages or no time between them.
  double rate_hz = 0.0;
  // Largest time between consecutive events of this channel (file order),
  // and the event time where it starts; 0 with fewer than two messages.
  double max_gap_s = 0.0;
  std::int64_t max_gap_from_utime = 0;
  // Span of the messages' own leading utime (min, max), over the messages
  // long enough to carry one.
  std::int64_t messages_with_utime = 0;
  std::int64_t message_min_utime = 0;
  std::int64_t message_max_utime = 0;
};

struct LogInfo {
  std::string path;
  std::int64_t file_bytes = 0;
  std::int64_t events = 0;
  std::int64_t start_utime = 0;  // first and last event timestamps, file order
  std::int64_t end_utime = 0;
  double duration_s = 0.0;
  // Events stamped earlier than the event before them (file order is kept).
  std::int64_t backward_steps = 0;
  std::int64_t messages_with_utime = 0;
  std::int64_t message_min_utime = 0;
  std::int64_t message_max_utime = 0;
  std::vector<ChannelInfo> channels;  // sorted by name
  std::vector<core::LogDamage> damage;
  std::string damage_report;  // empty for a clean log
};

// Reads the log once; a damaged log is described up to and around the damage.
// Throws core::LogError if the file cannot be opened or is not a log.
LogInfo logInfo(const std::string& path, const core::ReadProgress& progress = {});
LogInfo logInfo(const LogIndex& index);

// A readable summary: the spans, a table of channels, the damage.
std::string formatLogInfo(const LogInfo& info);

}  // namespace nadir::logs
