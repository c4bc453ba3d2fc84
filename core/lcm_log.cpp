#include "core/lcm_log.h"

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace nadir::core {
namespace {

constexpr std::uint32_t kEventMagic = 0xEDA1DA01;
constexpr std::size_t kHeaderSize = 4 + 8 + 8 + 4 + 4;
// LCM refuses channel names longer than this; anything longer is damage.
constexpr std::int32_t kMaxChannelLength = 1000;

std::uint64_t readBigEndian(const std::uint8_t* bytes, int count) {
  std::uint64_t value = 0;
  for (int i = 0; i < count; ++i) value = (value << 8) | bytes[i];
  return value;
}

void writeBigEndian(std::uint8_t* bytes, std::uint64_t value, int count) {
  for (int i = count - 1; i >= 0; --i) {
    bytes[i] = static_cast<std::uint8_t>(value & 0xFF);
    value >>= 8;
  }
}

std::string errnoText() { return std::strerror(errno); }

}  // namespace

LcmLogReader::LcmLogReader(const std::string& path) : path_(path) {
  file_ = std::fopen(path.c_str(), "rb");
  if (file_ == nullptr) throw LogError("cannot open LCM log " + path + ": " + errnoText());
  std::fseek(file_, 0, SEEK_END);
  file_size_ = std::ftell(file_);
  std::fseek(file_, 0, SEEK_SET);
  std::uint8_t magic[4];
  if (file_size_ > 0 &&
      (std::fread(magic, 1, 4, file_) != 4 || readBigEndian(magic, 4) != kEventMagic)) {
    std::fclose(file_);
    file_ = nullptr;
    throw LogError(path + " is not an LCM log: it does not start with the event magic 0xEDA1DA01");
  }
  std::fseek(file_, 0, SEEK_SET);
}

LcmLogReader::~LcmLogReader() {
  if (file_ != nullptr) std::fclose(file_);
}

std::optional<LogEvent> LcmLogReader::next() {
  std::optional<LogEvent> event = nextEvent();
  if (progress_) {
    const std::int64_t at = event ? tell() : file_size_;
    if (!event || at >= progress_next_at_) {
      progress_(at, file_size_);
      progress_next_at_ = at + progress_every_;
    }
  }
  return event;
}

void LcmLogReader::onProgress(ReadProgress progress, std::int64_t every_bytes) {
  progress_ = std::move(progress);
  progress_every_ = std::max<std::int64_t>(every_bytes, 1);
  progress_next_at_ = tell() + progress_every_;
}

std::optional<LogEvent> LcmLogReader::nextEvent() {
  while (true) {
    const std::int64_t offset = std::ftell(file_);
    const std::int64_t remaining = file_size_ - offset;
    if (remaining <= 0) return std::nullopt;
    if (remaining < static_cast<std::int64_t>(kHeaderSize)) {
      if (!resyncFrom(offset + 1)) return std::nullopt;
      continue;
    }
    std::uint8_t header[kHeaderSize];
    if (std::fread(header, 1, kHeaderSize, file_) != kHeaderSize) {
      throw LogError("read error in " + path_ + " at byte " + std::to_string(offset));
    }
    const auto magic = static_cast<std::uint32_t>(readBigEndian(header, 4));
    const auto channel_length = static_cast<std::int32_t>(readBigEndian(header + 20, 4));
    const auto data_length = static_cast<std::int32_t>(readBigEndian(header + 24, 4));
    const bool header_ok = magic == kEventMagic && channel_length > 0 &&
                           channel_length <= kMaxChannelLength && data_length >= 0;
    const std::int64_t body = static_cast<std::int64_t>(channel_length) + data_length;
    if (!header_ok || body > remaining - static_cast<std::int64_t>(kHeaderSize)) {
      if (!resyncFrom(offset + 1)) return std::nullopt;
      continue;
    }
    LogEvent event;
    event.offset = offset;
    event.event_number = static_cast<std::int64_t>(readBigEndian(header + 4, 8));
    event.timestamp_utime = static_cast<std::int64_t>(readBigEndian(header + 12, 8));
    event.channel.resize(static_cast<std::size_t>(channel_length));
    event.data.resize(static_cast<std::size_t>(data_length));
    if (std::fread(event.channel.data(), 1, event.channel.size(), file_) != event.channel.size() ||
        std::fread(event.data.data(), 1, event.data.size(), file_) != event.data.size()) {
      throw LogError("read error in " + path_ + " at byte " + std::to_string(offset));
    }
    const std::int64_t end = offset + static_cast<std::int64_t>(kHeaderSize) + body;
    if (!followedByEvent(end)) {
      // Damage follows this event, or its lengths are damaged and the next
      // event starts inside it: then it is skipped up to that event.
      const std::int64_t inside = findMagic(offset + 1, end);
      if (inside >= 0) {
        if (recordDamage(LogDamage::Kind::kSkipped, offset, inside - offset)) {
          skipped_bytes_ += inside - offset;
        }
        std::fseek(file_, inside, SEEK_SET);
        continue;
      }
      std::fseek(file_, end, SEEK_SET);
    }
    ++events_read_;
    return event;
  }
}

// True if the bytes at end start an event (or the start of one, at the end
// of the file), or end is the end of the file. Leaves the position unchanged
// only when true; callers seek afterwards either way.
bool LcmLogReader::followedByEvent(std::int64_t end) {
  if (end >= file_size_) return true;
  const auto count = static_cast<std::size_t>(std::min<std::int64_t>(4, file_size_ - end));
  std::uint8_t bytes[4];
  if (std::fread(bytes, 1, count, file_) != count) return false;
  std::uint8_t magic[4];
  writeBigEndian(magic, kEventMagic, 4);
  const bool ok = std::memcmp(bytes, magic, count) == 0;
  std::fseek(file_, end, SEEK_SET);
  return ok;
}

// Offset of the first event magic starting in [from, limit), or -1.
std::int64_t LcmLogReader::findMagic(std::int64_t from, std::int64_t limit) {
  std::fseek(file_, from, SEEK_SET);
  std::uint32_t window = 0;
  std::int64_t position = from;
  int c;
  while (position - 4 < limit - 1 && (c = std::fgetc(file_)) != EOF) {
    window = (window << 8) | static_cast<std::uint32_t>(c);
    ++position;
    if (position - from >= 4 && window == kEventMagic) return position - 4;
  }
  return -1;
}

// Looks for the next event magic at or after offset. If none, the bytes from the
// damaged event to the end are a truncated tail.
bool LcmLogReader::resyncFrom(std::int64_t offset) {
  const std::int64_t damaged_at = offset - 1;
  const std::int64_t event_start = findMagic(offset, file_size_);
  if (event_start >= 0) {
    if (recordDamage(LogDamage::Kind::kSkipped, damaged_at, event_start - damaged_at)) {
      skipped_bytes_ += event_start - damaged_at;
    }
    std::fseek(file_, event_start, SEEK_SET);
    return true;
  }
  truncated_tail_bytes_ = file_size_ - damaged_at;
  truncated_at_ = damaged_at;
  recordDamage(LogDamage::Kind::kTruncated, damaged_at, truncated_tail_bytes_);
  std::fseek(file_, file_size_, SEEK_SET);
  return false;
}

// Adds a damaged stretch unless an earlier read already covered it; adjacent
// skipped stretches merge. Returns false if it was known.
bool LcmLogReader::recordDamage(LogDamage::Kind kind, std::int64_t offset, std::int64_t bytes) {
  for (const LogDamage& known : damage_) {
    if (known.offset <= offset && offset + bytes <= known.offset + known.bytes) return false;
  }
  auto at =
      std::upper_bound(damage_.begin(), damage_.end(), offset,
                       [](std::int64_t value, const LogDamage& d) { return value < d.offset; });
  if (kind == LogDamage::Kind::kSkipped && at != damage_.begin()) {
    LogDamage& before = *(at - 1);
    if (before.kind == kind && before.offset + before.bytes == offset) {
      before.bytes += bytes;
      return true;
    }
  }
  damage_.insert(at, LogDamage{kind, offset, bytes});
  return true;
}

std::int64_t LcmLogReader::tell() const { return std::ftell(file_); }

void LcmLogReader::seek(std::int64_t offset) {
  if (offset < 0 || offset > file_size_) {
    throw LogError("cannot seek to byte " + std::to_string(offset) + " of " + path_ + " (" +
                   std::to_string(file_size_) + " bytes)");
  }
  std::fseek(file_, offset, SEEK_SET);
}

std::string LcmLogReader::damageReport() const {
  std::string report;
  if (skipped_bytes_ > 0) {
    report +=
        path_ + ": skipped " + std::to_string(skipped_bytes_) + " damaged bytes between events (";
    constexpr int kListed = 5;
    int listed = 0;
    int skipped_stretches = 0;
    for (const LogDamage& d : damage_) {
      if (d.kind != LogDamage::Kind::kSkipped) continue;
      ++skipped_stretches;
      if (listed == kListed) continue;
      if (listed > 0) report += ", ";
      report += std::to_string(d.bytes) + " bytes from byte " + std::to_string(d.offset);
      ++listed;
    }
    if (skipped_stretches > listed) {
      report += " and " + std::to_string(skipped_stretches - listed) + " more stretches";
    }
    report += ")";
  }
  if (truncated_tail_bytes_ > 0) {
    if (!report.empty()) report += "; ";
    report += path_ + ": truncated: the last " + std::to_string(truncated_tail_bytes_) +
              " bytes (from byte " + std::to_string(truncated_at_) +
              ") are an incomplete event and were ignored after " + std::to_string(events_read_) +
              " whole events";
  }
  return report;
}

LcmLogWriter::LcmLogWriter(const std::string& path) : path_(path) {
  file_ = std::fopen(path.c_str(), "wb");
  if (file_ == nullptr) throw LogError("cannot create LCM log " + path + ": " + errnoText());
}

LcmLogWriter::~LcmLogWriter() {
  if (file_ != nullptr) std::fclose(file_);
}

void LcmLogWriter::write(std::int64_t timestamp_utime, const std::string& channel, const void* data,
                         std::size_t size) {
  if (channel.empty() || channel.size() > static_cast<std::size_t>(kMaxChannelLength)) {
    throw LogError("cannot log channel name of " + std::to_string(channel.size()) + " bytes to " +
                   path_);
  }
  if (size > 0x7FFFFFFF) throw LogError("message too large for an LCM log: " + channel);
  std::uint8_t header[kHeaderSize];
  writeBigEndian(header, kEventMagic, 4);
  writeBigEndian(header + 4, static_cast<std::uint64_t>(next_event_number_), 8);
  writeBigEndian(header + 12, static_cast<std::uint64_t>(timestamp_utime), 8);
  writeBigEndian(header + 20, channel.size(), 4);
  writeBigEndian(header + 24, size, 4);
  if (std::fwrite(header, 1, kHeaderSize, file_) != kHeaderSize ||
      std::fwrite(channel.data(), 1, channel.size(), file_) != channel.size() ||
      (size > 0 && std::fwrite(data, 1, size, file_) != size)) {
    throw LogError("cannot write to " + path_ + ": " + errnoText());
  }
  ++next_event_number_;
}

void LcmLogWriter::flush() {
  if (std::fflush(file_) != 0) throw LogError("cannot flush " + path_ + ": " + errnoText());
}

}  // namespace nadir::core
