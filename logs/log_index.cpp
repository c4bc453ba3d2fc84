#include "logs/log_index.h"

#include <unordered_map>

#include "core/bus.h"

namespace nadir::logs {

LogIndex indexLog(const std::string& path, const core::ReadProgress& progress) {
  core::LcmLogReader reader(path);
  if (progress) reader.onProgress(progress);
  LogIndex index;
  index.path = path;
  index.file_bytes = reader.fileSize();
  std::unordered_map<std::string, std::int32_t> channel_ids;
  while (const std::optional<core::LogEvent> event = reader.next()) {
    auto [it, added] =
        channel_ids.try_emplace(event->channel, static_cast<std::int32_t>(index.channels.size()));
    if (added) index.channels.push_back(event->channel);
    const core::RawMessage raw{event->channel, event->data.data(), event->data.size(),
                               event->timestamp_utime};
    IndexedEvent entry;
    entry.offset = event->offset;
    entry.timestamp_utime = event->timestamp_utime;
    entry.message_utime = core::peekUtime(raw).value_or(kNoMessageUtime);
    entry.data_bytes = static_cast<std::int32_t>(event->data.size());
    entry.channel = it->second;
    index.events.push_back(entry);
  }
  index.damage = reader.damage();
  index.damage_report = reader.damageReport();
  return index;
}

}  // namespace nadir::logs
