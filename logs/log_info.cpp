#include "logs/log_info.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "core/clock.h"
#include "core/utc_time.h"

namespace nadir::logs {
namespace {

std::string formatted(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

std::string humanBytes(std::int64_t bytes) {
  const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB"};
  double value = static_cast<double>(bytes);
  int unit = 0;
  while (value >= 1024.0 && unit < 4) {
    value /= 1024.0;
    ++unit;
  }
  if (unit == 0) return std::to_string(bytes) + " B";
  return formatted("%.1f", value) + " " + units[unit];
}

// Seconds of an absolute utime, microsecond precision.
std::string absoluteSeconds(std::int64_t utime) {
  return formatted("%.6f", core::secondsFromUtime(utime));
}

std::string relativeSeconds(std::int64_t utime, std::int64_t origin) {
  return formatted("%.3f", core::secondsFromUtime(utime - origin));
}

// Left-aligns the first column, right-aligns the others.
std::string table(const std::vector<std::vector<std::string>>& rows, const std::string& indent) {
  std::vector<std::size_t> widths;
  for (const auto& row : rows) {
    widths.resize(std::max(widths.size(), row.size()));
    for (std::size_t c = 0; c < row.size(); ++c) widths[c] = std::max(widths[c], row[c].size());
  }
  std::string out;
  for (const auto& row : rows) {
    std::string line = indent;
    for (std::size_t c = 0; c < row.size(); ++c) {
      const std::string pad(widths[c] - row[c].size(), ' ');
      if (c > 0) line += "  ";
      line += c == 0 ? row[c] + pad : pad + row[c];
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out += line + "\n";
  }
  return out;
}

// ", from 2024-06-21T10:00:00Z" for a time that is a date (after 2000), else "".
std::string fromDate(std::int64_t utime) {
  return utime >= core::kYear2000Utime ? ", from " + core::utcFromUtime(utime) : std::string();
}

}  // namespace

LogInfo logInfo(const std::string& path, const core::ReadProgress& progress) {
  return logInfo(indexLog(path, progress));
}

LogInfo logInfo(const LogIndex& index) {
  LogInfo info;
  info.path = index.path;
  info.file_bytes = index.file_bytes;
  info.events = static_cast<std::int64_t>(index.events.size());
  info.start_utime = index.startUtime();
  info.end_utime = index.endUtime();
  info.duration_s = core::secondsFromUtime(info.end_utime - info.start_utime);
  info.damage = index.damage;
  info.damage_report = index.damage_report;

  std::vector<ChannelInfo> channels(index.channels.size());
  for (std::size_t i = 0; i < channels.size(); ++i) channels[i].channel = index.channels[i];
  for (std::size_t i = 0; i < index.events.size(); ++i) {
    const IndexedEvent& event = index.events[i];
    if (i > 0 && event.timestamp_utime < index.events[i - 1].timestamp_utime) {
      ++info.backward_steps;
    }
    ChannelInfo& channel = channels[static_cast<std::size_t>(event.channel)];
    if (channel.messages == 0) {
      channel.first_utime = event.timestamp_utime;
    } else {
      const double gap_s = core::secondsFromUtime(event.timestamp_utime - channel.last_utime);
      if (channel.messages == 1 || gap_s > channel.max_gap_s) {
        channel.max_gap_s = gap_s;
        channel.max_gap_from_utime = channel.last_utime;
      }
    }
    channel.last_utime = event.timestamp_utime;
    ++channel.messages;
    channel.bytes += event.data_bytes;
    if (event.message_utime != kNoMessageUtime) {
      if (channel.messages_with_utime == 0) {
        channel.message_min_utime = channel.message_max_utime = event.message_utime;
      }
      channel.message_min_utime = std::min(channel.message_min_utime, event.message_utime);
      channel.message_max_utime = std::max(channel.message_max_utime, event.message_utime);
      ++channel.messages_with_utime;
    }
  }
  for (ChannelInfo& channel : channels) {
    const std::int64_t span_utime = channel.last_utime - channel.first_utime;
    if (channel.messages >= 2 && span_utime > 0) {
      channel.rate_hz =
          static_cast<double>(channel.messages - 1) / core::secondsFromUtime(span_utime);
    }
    if (channel.messages_with_utime > 0) {
      if (info.messages_with_utime == 0) {
        info.message_min_utime = channel.message_min_utime;
        info.message_max_utime = channel.message_max_utime;
      }
      info.message_min_utime = std::min(info.message_min_utime, channel.message_min_utime);
      info.message_max_utime = std::max(info.message_max_utime, channel.message_max_utime);
      info.messages_with_utime += channel.messages_with_utime;
    }
  }
  std::sort(channels.begin(), channels.end(),
            [](const ChannelInfo& a, const ChannelInfo& b) { return a.channel < b.channel; });
  info.channels = std::move(channels);
  return info;
}

std::string formatLogInfo(const LogInfo& info) {
  std::ostringstream out;
  out << info.path << ": " << humanBytes(info.file_bytes) << " (" << info.file_bytes << " bytes), "
      << info.events << " events, " << info.channels.size() << " channels, "
      << formatted("%.3f", info.duration_s) << " s\n";
  if (info.events > 0) {
    out << "  event time    " << absoluteSeconds(info.start_utime) << " .. "
        << absoluteSeconds(info.end_utime) << " s (" << formatted("%.3f", info.duration_s) << " s)"
        << fromDate(info.start_utime) << "\n";
  }
  if (info.messages_with_utime > 0) {
    out << "  message time  " << absoluteSeconds(info.message_min_utime) << " .. "
        << absoluteSeconds(info.message_max_utime) << " s ("
        << formatted("%.3f",
                     core::secondsFromUtime(info.message_max_utime - info.message_min_utime))
        << " s), the leading utime of " << info.messages_with_utime << " messages"
        << fromDate(info.message_min_utime) << "\n";
  }
  if (info.backward_steps > 0) {
    out << "  note: the event time goes backwards " << info.backward_steps
        << " times (tools keep the file order)\n";
  }
  if (!info.channels.empty()) {
    out << "\n";
    std::vector<std::vector<std::string>> rows;
    rows.push_back({"channel", "messages", "bytes", "first s", "last s", "rate Hz", "max gap s",
                    "gap at s", "message time s"});
    for (const ChannelInfo& c : info.channels) {
      const std::string message_span = c.messages_with_utime == 0
                                           ? "-"
                                           : absoluteSeconds(c.message_min_utime) + " .. " +
                                                 absoluteSeconds(c.message_max_utime);
      rows.push_back(
          {c.channel, std::to_string(c.messages), humanBytes(c.bytes),
           relativeSeconds(c.first_utime, info.start_utime),
           relativeSeconds(c.last_utime, info.start_utime), formatted("%.2f", c.rate_hz),
           formatted("%.4f", c.max_gap_s),
           c.messages < 2 ? "-" : relativeSeconds(c.max_gap_from_utime, info.start_utime),
           message_span});
    }
    out << table(rows, "  ");
    out << "  (first, last and gap times are event times after the log's first event)\n";
  }
  out << "\n";
  if (info.damage.empty()) {
    out << "  damage: none\n";
  } else {
    out << "  damage: " << info.damage.size()
        << (info.damage.size() == 1 ? " stretch" : " stretches") << "\n";
    for (const core::LogDamage& d : info.damage) {
      if (d.kind == core::LogDamage::Kind::kSkipped) {
        out << "    skipped    " << d.bytes << " bytes from byte " << d.offset
            << " (not an event; the reader resumed at the next event)\n";
      } else {
        out << "    truncated  " << d.bytes << " bytes from byte " << d.offset
            << " (an incomplete last event)\n";
      }
    }
    out << "  warning: " << info.damage_report << "\n";
  }
  return out.str();
}

}  // namespace nadir::logs
