#pragma once
// One pass over an LCM log that remembers where every event is, so tools can
// seek by time and read events on demand without keeping their data.

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/lcm_log.h"

namespace nadir::logs {

// IndexedEvent::message_utime of a message too short to carry a utime.
inline constexpr std::int64_t kNoMessageUtime = std::numeric_limits<std::int64_t>::min();

struct IndexedEvent {
  std::int64_t offset = 0;           // byte offset of the event in the file
  std::int64_t timestamp_utime = 0;  // the event's timestamp
  // The message's own leading int64 utime (core::peekUtime), or kNoMessageUtime.
  std::int64_t message_utime = kNoMessageUtime;
  std::int32_t data_bytes = 0;
  std::int32_t channel = 0;  // index into LogIndex::channels
};

struct LogIndex {
  std::string path;
  std::int64_t file_bytes = 0;
  std::vector<std::string> channels;  // in order of first appearance
  std::vector<IndexedEvent> events;   // whole events, in file order
  std::vector<core::LogDamage> damage;
  std::string damage_report;  // empty for a clean log

  // Timestamps of the first and last events in file order (0 if empty).
  std::int64_t startUtime() const { return events.empty() ? 0 : events.front().timestamp_utime; }
  std::int64_t endUtime() const { return events.empty() ? 0 : events.back().timestamp_utime; }
};

// Reads the whole log once. A damaged or truncated log is indexed up to and
// around the damage, which is reported in damage/damage_report. Throws
// core::LogError if the file cannot be opened or is not a log.
// progress is told how far the reading has come (core::LcmLogReader::onProgress).
LogIndex indexLog(const std::string& path, const core::ReadProgress& progress = {});

}  // namespace nadir::logs
