#pragma once
// Reader and writer of the LCM event log format (what lcm-logger writes and
// lcm-logplayer reads), with errors that say what is wrong and where.
//
// Each event: magic 0xEDA1DA01 (int32), event number (int64), timestamp in
// microseconds (int64), channel length (int32), data length (int32), channel
// bytes, data bytes; all integers big-endian.

#include <cstdint>
#include <cstdio>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace nadir::core {

class LogError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct LogEvent {
  std::int64_t event_number = 0;
  std::int64_t timestamp_utime = 0;
  std::string channel;
  std::vector<std::uint8_t> data;
  // Byte offset of the event's first header byte in the file (set by the reader).
  std::int64_t offset = -1;
};

// One damaged stretch of a log file.
struct LogDamage {
  enum class Kind {
    kSkipped,    // bytes between two whole events that are not an event
    kTruncated,  // an incomplete event at the end of the file
  };
  Kind kind = Kind::kSkipped;
  std::int64_t offset = 0;  // first damaged byte
  std::int64_t bytes = 0;
};

// Told how far a reader has come: bytes read (the next event's offset) of the
// file's size; once more at the end with both equal.
using ReadProgress = std::function<void(std::int64_t bytes_read, std::int64_t file_bytes)>;

class LcmLogReader {
 public:
  // Throws LogError if the file cannot be opened or does not start with an event.
  explicit LcmLogReader(const std::string& path);
  ~LcmLogReader();
  LcmLogReader(const LcmLogReader&) = delete;
  LcmLogReader& operator=(const LcmLogReader&) = delete;

  // The next event, or nothing at the end of the log. A damaged event in the
  // middle is skipped up to the next event magic and counted (so is an event
  // whose length fields put the next event's start inside it); a truncated
  // last event ends the log and is reported by truncatedTailBytes().
  std::optional<LogEvent> next();
  // Calls progress from next() each time another every_bytes have been read,
  // and at the end.
  void onProgress(ReadProgress progress, std::int64_t every_bytes = 64 << 20);

  const std::string& path() const { return path_; }
  std::int64_t eventsRead() const { return events_read_; }
  // Bytes skipped while resynchronising after damage.
  std::int64_t skippedBytes() const { return skipped_bytes_; }
  // Size of an incomplete event at the end of the file (0 if none).
  std::int64_t truncatedTailBytes() const { return truncated_tail_bytes_; }
  // Human-readable account of damage found so far, with byte offsets; empty if
  // the log was clean.
  std::string damageReport() const;
  // The damaged stretches found so far, in file order. Reading a stretch again
  // after seek() does not count it twice.
  const std::vector<LogDamage>& damage() const { return damage_; }

  // Size of the file when it was opened, bytes.
  std::int64_t fileSize() const { return file_size_; }
  // Byte offset the next read starts from.
  std::int64_t tell() const;
  // Continues reading from offset, normally an event's LogEvent::offset (a
  // position inside an event is resynchronised like damage). Throws LogError
  // if offset is outside the file.
  void seek(std::int64_t offset);

 private:
  std::optional<LogEvent> nextEvent();
  bool resyncFrom(std::int64_t offset);
  std::int64_t findMagic(std::int64_t from, std::int64_t limit);
  bool followedByEvent(std::int64_t end);
  bool recordDamage(LogDamage::Kind kind, std::int64_t offset, std::int64_t bytes);

  std::string path_;
  std::FILE* file_ = nullptr;
  std::int64_t file_size_ = 0;
  std::int64_t events_read_ = 0;
  std::int64_t skipped_bytes_ = 0;
  std::int64_t truncated_tail_bytes_ = 0;
  std::int64_t truncated_at_ = -1;
  std::vector<LogDamage> damage_;
  ReadProgress progress_;
  std::int64_t progress_every_ = 0;
  std::int64_t progress_next_at_ = 0;
};

class LcmLogWriter {
 public:
  // Creates or truncates path. Throws LogError naming the path on failure.
  explicit LcmLogWriter(const std::string& path);
  ~LcmLogWriter();
  LcmLogWriter(const LcmLogWriter&) = delete;
  LcmLogWriter& operator=(const LcmLogWriter&) = delete;

  // Appends one event; event numbers count up from 0.
  void write(std::int64_t timestamp_utime, const std::string& channel, const void* data,
             std::size_t size);
  void flush();

  const std::string& path() const { return path_; }
  std::int64_t eventsWritten() const { return next_event_number_; }

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
  std::int64_t next_event_number_ = 0;
};

}  // namespace nadir::core
