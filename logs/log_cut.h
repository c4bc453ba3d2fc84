#pragma once
// Cuts a time window and a set of channels out of an LCM log into a new,
// valid log (events renumbered from 0, timestamps and bytes unchanged).

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/lcm_log.h"

namespace nadir::logs {

struct CutOptions {
  // The window [start, end) in event time, relative to the first event's
  // timestamp, seconds; unset means from the beginning / to the end.
  std::optional<double> start_s;
  std::optional<double> end_s;
  // The same bounds as absolute event timestamps; when set they override
  // start_s / end_s.
  std::optional<std::int64_t> start_utime;
  std::optional<std::int64_t> end_utime;
  // Keep channels whose whole name matches this POSIX extended regex (empty: all)...
  std::string channels;
  // ...and drop those matching this one (empty: none).
  std::string exclude;
  // Told how far the reading of in has come; may be empty.
  core::ReadProgress progress;
};

struct CutResult {
  std::int64_t events_read = 0;  // whole events in the input
  std::int64_t events_written = 0;
  std::int64_t bytes_written = 0;        // size of the output file
  std::int64_t first_written_utime = 0;  // timestamps of the first and last
  std::int64_t last_written_utime = 0;   // written events (0 if none)
  std::map<std::string, std::int64_t> written_per_channel;
  std::vector<core::LogDamage> damage;  // damage met in the input
  std::string damage_report;            // empty for a clean input
};

// Writes the selected events of in to out. A damaged input is cut from what
// can be read (up to a truncation, around damage in the middle) and the
// damage is returned. Throws core::LogError if in cannot be read or out
// cannot be written, std::invalid_argument for a bad regex, an empty window,
// or out naming the same file as in.
CutResult cutLog(const std::string& in, const std::string& out, const CutOptions& options);

}  // namespace nadir::logs
