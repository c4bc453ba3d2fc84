#include "logs/log_cut.h"

#include <filesystem>
#include <limits>
#include <stdexcept>

#include "core/clock.h"
#include "logs/channel_filter.h"

namespace nadir::logs {

CutResult cutLog(const std::string& in, const std::string& out, const CutOptions& options) {
  const ChannelFilter filter(options.channels, options.exclude);
  const auto relative_start = options.start_s.value_or(0.0);
  if (options.start_s && options.end_s && *options.end_s <= *options.start_s) {
    throw std::invalid_argument("the window to cut is empty: end " +
                                std::to_string(*options.end_s) + " s is not after start " +
                                std::to_string(*options.start_s) + " s");
  }
  if (options.start_utime && options.end_utime && *options.end_utime <= *options.start_utime) {
    throw std::invalid_argument("the window to cut is empty: end utime " +
                                std::to_string(*options.end_utime) + " is not after start " +
                                std::to_string(*options.start_utime));
  }
  std::error_code error;
  if (std::filesystem::equivalent(in, out, error)) {
    throw std::invalid_argument("cannot cut " + in + " into itself");
  }

  core::LcmLogReader reader(in);
  if (options.progress) reader.onProgress(options.progress);
  core::LcmLogWriter writer(out);
  CutResult result;
  std::int64_t start_utime = std::numeric_limits<std::int64_t>::min();
  std::int64_t end_utime = std::numeric_limits<std::int64_t>::max();
  bool first = true;
  while (const std::optional<core::LogEvent> event = reader.next()) {
    if (first) {
      // Relative bounds count from the first event's timestamp.
      first = false;
      const std::int64_t log_start = event->timestamp_utime;
      if (options.start_utime) {
        start_utime = *options.start_utime;
      } else if (options.start_s) {
        start_utime = log_start + core::utimeFromSeconds(relative_start);
      }
      if (options.end_utime) {
        end_utime = *options.end_utime;
      } else if (options.end_s) {
        end_utime = log_start + core::utimeFromSeconds(*options.end_s);
      }
    }
    ++result.events_read;
    if (event->timestamp_utime < start_utime || event->timestamp_utime >= end_utime) continue;
    if (!filter.keeps(event->channel)) continue;
    writer.write(event->timestamp_utime, event->channel, event->data.data(), event->data.size());
    if (result.events_written == 0) result.first_written_utime = event->timestamp_utime;
    result.last_written_utime = event->timestamp_utime;
    ++result.events_written;
    ++result.written_per_channel[event->channel];
  }
  writer.flush();
  result.bytes_written = static_cast<std::int64_t>(std::filesystem::file_size(out));
  result.damage = reader.damage();
  result.damage_report = reader.damageReport();
  return result;
}

}  // namespace nadir::logs
