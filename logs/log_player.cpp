#include "logs/log_player.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "core/clock.h"
#include "lcmtypes/codec.h"
#include "logs/channel_filter.h"

namespace nadir::logs {
namespace {

// A loop shorter than this (in log time) is stretched to it, so a log whose
// selected events all share one timestamp does not loop without end.
constexpr std::int64_t kMinLoopUtime = 1000;
// Bounds the work of one update() after a long stall on a short loop.
constexpr int kMaxWrapsPerUpdate = 1000;

void checkSpeed(double speed) {
  if (!(speed > 0.0) || !std::isfinite(speed)) {
    throw std::invalid_argument("play speed must be a number > 0, not " + std::to_string(speed));
  }
}

}  // namespace

ImageEncoding ImageEncoding::parse(const std::string& text) {
  ImageEncoding encoding;
  if (text == "as-recorded") return encoding;
  if (text == "raw") {
    encoding.kind = Kind::kRaw;
    return encoding;
  }
  if (text == "jpeg" || text.rfind("jpeg:", 0) == 0) {
    encoding.kind = Kind::kJpeg;
    if (text == "jpeg") return encoding;
    const std::string quality = text.substr(5);
    std::size_t used = 0;
    int value = 0;
    try {
      value = std::stoi(quality, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (quality.empty() || used != quality.size() || value < 1 || value > 100) {
      throw std::invalid_argument("'" + text + "': a JPEG quality is a whole number 1-100");
    }
    encoding.jpeg_quality = value;
    return encoding;
  }
  throw std::invalid_argument("an image encoding is as-recorded, raw, jpeg or jpeg:QUALITY, not '" +
                              text + "'");
}

std::string ImageEncoding::name() const {
  switch (kind) {
    case Kind::kRaw:
      return "raw";
    case Kind::kJpeg:
      return "jpeg:" + std::to_string(jpeg_quality);
    case Kind::kAsRecorded:
      break;
  }
  return "as-recorded";
}

std::pair<std::string, std::string> parseRemap(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size()) {
    throw std::invalid_argument("a channel remap is FROM=TO, not '" + text + "'");
  }
  return {text.substr(0, eq), text.substr(eq + 1)};
}

std::int64_t LogPlayer::steadyClockUtime() {
  using namespace std::chrono;
  return duration_cast<microseconds>(steady_clock::now().time_since_epoch()).count();
}

LogPlayer::LogPlayer(const std::string& path, core::Bus& bus, PlayerOptions options, Clock clock)
    : index_(indexLog(path)),
      bus_(bus),
      options_(std::move(options)),
      clock_(std::move(clock)),
      reader_(path),
      speed_(options_.speed) {
  checkSpeed(speed_);
  if (!clock_) throw std::invalid_argument("LogPlayer needs a clock");
  if (!std::isfinite(options_.start_s) || options_.start_s < 0.0 ||
      options_.start_s > durationS() + 1e-6) {
    char span[96];
    std::snprintf(span, sizeof(span),
                  "start %.3f s is outside the log (0 .. %.3f s): ", options_.start_s, durationS());
    throw std::invalid_argument(span + path);
  }
  const ChannelFilter filter(options_.channels);
  for (const std::string& name : index_.channels) {
    channel_selected_.push_back(filter.keeps(name));
    const auto renamed = options_.remap.find(name);
    channel_out_.push_back(renamed == options_.remap.end() ? name : renamed->second);
  }
  std::int64_t running_max = std::numeric_limits<std::int64_t>::min();
  for (std::size_t i = 0; i < index_.events.size(); ++i) {
    const IndexedEvent& event = index_.events[i];
    if (!channel_selected_[static_cast<std::size_t>(event.channel)]) continue;
    selected_.push_back(i);
    running_max = std::max(running_max, event.timestamp_utime);
    running_max_utime_.push_back(running_max);
  }
  loop_start_utime_ =
      std::min(index_.startUtime() + core::utimeFromSeconds(options_.start_s), index_.endUtime());
  loop_start_cursor_ = firstSelectedAtOrAfter(loop_start_utime_);
  cursor_ = loop_start_cursor_;
  position_utime_ = loop_start_utime_;
  anchor();
}

std::int64_t LogPlayer::selectedTime(std::size_t i) const {
  return index_.events[selected_[i]].timestamp_utime;
}

std::size_t LogPlayer::firstSelectedAtOrAfter(std::int64_t log_utime) const {
  return static_cast<std::size_t>(
      std::lower_bound(running_max_utime_.begin(), running_max_utime_.end(), log_utime) -
      running_max_utime_.begin());
}

void LogPlayer::anchor() {
  anchor_clock_ = clock_();
  anchor_log_utime_ = position_utime_;
}

int LogPlayer::sendUpTo(std::int64_t log_utime) {
  int sent = 0;
  while (cursor_ < selected_.size()) {
    const IndexedEvent& entry = index_.events[selected_[cursor_]];
    if (entry.timestamp_utime > log_utime) break;
    if (reader_.tell() != entry.offset) reader_.seek(entry.offset);
    const std::optional<core::LogEvent> event = reader_.next();
    if (!event || event->offset != entry.offset) {
      throw core::LogError(index_.path + " changed while playing: no event at byte " +
                           std::to_string(entry.offset) + " any more");
    }
    send(channel_out_[static_cast<std::size_t>(entry.channel)], *event);
    ++cursor_;
    ++sent;
    ++events_sent_;
  }
  position_utime_ = std::max(position_utime_, log_utime);
  return sent;
}

void LogPlayer::send(const std::string& channel, const core::LogEvent& event) {
  const ImageEncoding& encoding = options_.image_encoding;
  msg::Bytes reencoded;
  if (encoding.kind != ImageEncoding::Kind::kAsRecorded &&
      msg::isType<msg::Image>(event.data.data(), event.data.size())) {
    // An image that does not decode goes out as it was: the receiver counts it.
    try {
      msg::Image image = msg::decode<msg::Image>(event.data.data(), event.data.size());
      const bool is_jpeg = msg::isJpegImage(event.data.data(), event.data.size());
      const bool want_jpeg = encoding.kind == ImageEncoding::Kind::kJpeg;
      if (is_jpeg != want_jpeg) {
        image.jpeg_quality = want_jpeg ? encoding.jpeg_quality : 0;
        reencoded = msg::encode(image);
        ++images_reencoded_;
      }
    } catch (const std::exception&) {
      reencoded.clear();
    }
  }
  const std::uint8_t* data = reencoded.empty() ? event.data.data() : reencoded.data();
  const std::size_t size = reencoded.empty() ? event.data.size() : reencoded.size();
  bus_.publish(channel, data, size, event.timestamp_utime);
  bytes_sent_ += static_cast<std::int64_t>(size);
  channel_bytes_[channel] += static_cast<std::int64_t>(size);
}

int LogPlayer::update() {
  if (paused_) return 0;
  const std::int64_t now = clock_();
  int sent = 0;
  for (int wraps = 0;; ++wraps) {
    const std::int64_t target =
        anchor_log_utime_ + std::llround(static_cast<double>(now - anchor_clock_) * speed_);
    if (!options_.loop || finished()) {
      sent += sendUpTo(target);
      break;
    }
    const std::int64_t loop_end =
        std::max(running_max_utime_.back(), loop_start_utime_ + kMinLoopUtime);
    sent += sendUpTo(std::min(target, loop_end));
    if (target <= loop_end) break;
    // Everything up to the end was sent: go back to the start, keeping the
    // play time that was left over.
    anchor_clock_ += std::max<std::int64_t>(
        0, std::llround(std::ceil(static_cast<double>(loop_end - anchor_log_utime_) / speed_)));
    anchor_log_utime_ = loop_start_utime_;
    position_utime_ = loop_start_utime_;
    cursor_ = loop_start_cursor_;
    ++loops_;
    if (wraps + 1 >= kMaxWrapsPerUpdate) {
      anchor_clock_ = now;
      break;
    }
  }
  return sent;
}

int LogPlayer::stepTo(std::int64_t log_utime) {
  const int sent = sendUpTo(log_utime);
  anchor();
  return sent;
}

void LogPlayer::pause() {
  if (paused_) return;
  update();
  paused_ = true;
}

void LogPlayer::resume() {
  if (!paused_) return;
  paused_ = false;
  anchor();
}

void LogPlayer::togglePause() {
  if (paused_) {
    resume();
  } else {
    pause();
  }
}

void LogPlayer::setSpeed(double speed) {
  checkSpeed(speed);
  update();
  speed_ = speed;
  anchor();
}

void LogPlayer::seek(double t_s) {
  const double clamped = std::clamp(std::isfinite(t_s) ? t_s : 0.0, 0.0, durationS());
  position_utime_ =
      std::min(index_.startUtime() + core::utimeFromSeconds(clamped), index_.endUtime());
  cursor_ = firstSelectedAtOrAfter(position_utime_);
  anchor();
}

void LogPlayer::seekBy(double dt_s) { seek(positionS() + dt_s); }

double LogPlayer::positionS() const {
  return core::secondsFromUtime(std::min(position_utime_, index_.endUtime()) - index_.startUtime());
}

double LogPlayer::durationS() const {
  return core::secondsFromUtime(index_.endUtime() - index_.startUtime());
}

bool LogPlayer::finished() const {
  if (cursor_ < selected_.size()) return false;
  return !options_.loop || loop_start_cursor_ >= selected_.size();
}

std::optional<std::int64_t> LogPlayer::microsUntilNextEvent() const {
  if (paused_ || finished()) return std::nullopt;
  std::int64_t due_log_utime;
  if (cursor_ < selected_.size()) {
    due_log_utime = selectedTime(cursor_);
  } else {
    // Looping: the next thing due is the wrap, just after the loop's end.
    due_log_utime = std::max(running_max_utime_.back(), loop_start_utime_ + kMinLoopUtime) + 1;
  }
  const double wait = std::ceil(static_cast<double>(due_log_utime - anchor_log_utime_) / speed_);
  const std::int64_t due_clock = anchor_clock_ + static_cast<std::int64_t>(wait);
  return std::max<std::int64_t>(0, due_clock - clock_());
}

std::string LogPlayer::statusLine() const {
  const char* state = paused_ ? "paused" : finished() ? "finished" : "playing";
  char text[200];
  std::snprintf(text, sizeof(text), "%9.3f / %.3f s  x%-6.4g %-8s %lld sent", positionS(),
                durationS(), speed_, state, static_cast<long long>(events_sent_));
  std::string line = text;
  if (options_.loop) line += "  loop " + std::to_string(loops_ + 1);
  return line;
}

}  // namespace nadir::logs
