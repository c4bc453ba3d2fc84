#pragma once
// Plays an LCM log onto any core::Bus at a chosen speed, with pause, seek,
// loop, a channel filter and channel renaming. The log is indexed once, so a
// seek is a binary search; event data is read from the file as it is sent.
//
// Time: the play position is a log time (an event timestamp, utime). The
// player is driven either by update(), which advances the position by the
// time its clock moved since the last anchor times the speed, or by stepTo(),
// which moves it to a given log time. Both send every event that became due,
// in file order; an event is due when its timestamp is at or before the
// position. Nothing sleeps: a caller waits microsUntilNextEvent() itself, and
// a test drives a fake clock.

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/bus.h"
#include "core/lcm_log.h"
#include "logs/log_index.h"

namespace nadir::logs {

// How camera images (image_t) go out: as the log holds them, or each one
// re-encoded raw (GRAY/RGB) or as JPEG of a quality.
struct ImageEncoding {
  enum class Kind { kAsRecorded, kRaw, kJpeg };
  Kind kind = Kind::kAsRecorded;
  int jpeg_quality = 90;  // 1-100, for kJpeg

  // "as-recorded", "raw", "jpeg" or "jpeg:Q"; throws std::invalid_argument.
  static ImageEncoding parse(const std::string& text);
  std::string name() const;
};

struct PlayerOptions {
  double speed = 1.0;    // times real time, > 0
  double start_s = 0.0;  // where to begin (and loop back to), s after the log's first event
  bool loop = false;     // after the last event, go back to start_s
  // Channel renaming, FROM -> TO (whole names); applied after the filter.
  std::map<std::string, std::string> remap{};
  // Send only channels (as named in the log) that fully match this POSIX
  // extended regex; empty: every channel.
  std::string channels{};
  ImageEncoding image_encoding{};
};

// Parses "FROM=TO" into {FROM, TO}; throws std::invalid_argument if either is empty.
std::pair<std::string, std::string> parseRemap(const std::string& text);

class LogPlayer {
 public:
  // Monotonic microseconds; the default reads std::chrono::steady_clock.
  using Clock = std::function<std::int64_t()>;
  static std::int64_t steadyClockUtime();

  // Indexes path (reporting damage, see damageReport()) and positions at
  // options.start_s, anchored at clock(). bus must outlive the player.
  // Throws core::LogError for an unreadable file, std::invalid_argument for
  // a bad option.
  LogPlayer(const std::string& path, core::Bus& bus, PlayerOptions options = {},
            Clock clock = steadyClockUtime);

  // Sends every event due at the clock's current time (looping if asked);
  // returns how many were sent. Does nothing while paused.
  int update();
  // Moves the position to log_utime (absolute), sending every event due up
  // to it in file order, without looping; re-anchors the clock there.
  int stepTo(std::int64_t log_utime);

  // Pausing first sends what is due; resuming continues from the same position.
  void pause();
  void resume();
  void togglePause();
  bool paused() const { return paused_; }

  // Sends what is due at the old speed, then continues at speed (> 0).
  void setSpeed(double speed);
  double speed() const { return speed_; }

  // Jumps to t_s after the log's first event (clamped to the log), sending
  // nothing; events stamped at or after that time follow.
  void seek(double t_s);
  void seekBy(double dt_s);

  // The play position: absolute log time, and seconds after the first event.
  std::int64_t positionUtime() const { return position_utime_; }
  double positionS() const;
  double durationS() const;
  // True once every selected event was sent and loop is off.
  bool finished() const;
  // Clock microseconds until the next event is due (0 if one is due now);
  // nothing while paused or finished.
  std::optional<std::int64_t> microsUntilNextEvent() const;

  std::int64_t eventsSent() const { return events_sent_; }
  // Bytes put on the bus (after re-encoding images), in all and by channel as sent.
  std::int64_t bytesSent() const { return bytes_sent_; }
  const std::map<std::string, std::int64_t>& bytesSentByChannel() const { return channel_bytes_; }
  // Images re-encoded, and those that were not images after all (sent as they were).
  std::int64_t imagesReencoded() const { return images_reencoded_; }
  int loops() const { return loops_; }
  // Events (of the whole log) and the ones the channel filter selects.
  std::int64_t events() const { return static_cast<std::int64_t>(index_.events.size()); }
  std::int64_t selectedEvents() const { return static_cast<std::int64_t>(selected_.size()); }
  const LogIndex& index() const { return index_; }
  // Damage met while indexing (empty for a clean log).
  const std::string& damageReport() const { return index_.damage_report; }
  // "  12.345 / 60.000 s  x1.00  playing  1234 sent", for a status line.
  std::string statusLine() const;

 private:
  int sendUpTo(std::int64_t log_utime);
  void send(const std::string& channel, const core::LogEvent& event);
  void anchor();
  std::size_t firstSelectedAtOrAfter(std::int64_t log_utime) const;
  std::int64_t selectedTime(std::size_t i) const;

  LogIndex index_;
  core::Bus& bus_;
  PlayerOptions options_;
  Clock clock_;
  core::LcmLogReader reader_;
  std::vector<bool> channel_selected_;           // by channel id
  std::vector<std::string> channel_out_;         // by channel id, after remap
  std::vector<std::size_t> selected_;            // indices into index_.events
  std::vector<std::int64_t> running_max_utime_;  // over selected_, for seeking
  std::size_t cursor_ = 0;                       // next entry of selected_ to send
  std::int64_t loop_start_utime_ = 0;
  std::size_t loop_start_cursor_ = 0;
  std::int64_t position_utime_ = 0;
  std::int64_t anchor_clock_ = 0;
  std::int64_t anchor_log_utime_ = 0;
  double speed_ = 1.0;
  bool paused_ = false;
  std::int64_t events_sent_ = 0;
  std::int64_t bytes_sent_ = 0;
  std::int64_t images_reencoded_ = 0;
  std::map<std::string, std::int64_t> channel_bytes_;
  int loops_ = 0;
};

}  // namespace nadir::logs
