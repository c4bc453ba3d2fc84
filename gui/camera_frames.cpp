#include "gui/camera_frames.h"

#include <algorithm>
#include <filesystem>
#include <numeric>
#include <stdexcept>
#include <utility>

#include "core/bus.h"
#include "core/lcm_log.h"
#include "core/trajectory.h"
#include "lcmtypes/codec.h"

namespace nadir::gui {

CameraFrame decodeCameraFrame(const void* data, std::size_t size, std::int64_t number) {
  CameraFrame frame;
  frame.number = number;
  try {
    const msg::Image image = msg::decode<msg::Image>(data, size);
    frame.t_s = core::stampFromUtime(image.utime);
    frame.pixels = image.pixels;
  } catch (const msg::DecodeError& e) {
    frame.error = "not an image_t (" + std::to_string(size) + " bytes)";
  } catch (const msg::InvalidMessage& e) {
    if (const std::optional<std::int64_t> utime = core::peekUtime(
            core::RawMessage{{}, static_cast<const std::uint8_t*>(data), size, 0})) {
      frame.t_s = core::stampFromUtime(*utime);
    }
    frame.error = e.what();
  }
  return frame;
}

LogCameraFrames::LogCameraFrames(const std::string& log_path, const std::string& channel)
    : log_path_(log_path),
      channel_(channel),
      reader_(std::make_unique<core::LcmLogReader>(log_path)) {
  std::vector<double> stamps_s;
  std::vector<std::int64_t> offsets;
  while (const std::optional<core::LogEvent> event = reader_->next()) {
    if (event->channel != channel_) continue;
    // The stamp is image_t's first field; an event too short for it sorts first.
    core::RawMessage raw;
    raw.channel = event->channel;
    raw.data = event->data.data();
    raw.size = event->data.size();
    stamps_s.push_back(core::stampFromUtime(core::peekUtime(raw).value_or(0)));
    offsets.push_back(event->offset);
  }
  std::vector<std::size_t> order(stamps_s.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return stamps_s[a] < stamps_s[b]; });
  for (const std::size_t i : order) {
    stamps_s_.push_back(stamps_s[i]);
    offsets_.push_back(offsets[i]);
    numbers_.push_back(static_cast<std::int64_t>(i));
  }
}

LogCameraFrames::~LogCameraFrames() = default;

std::optional<CameraFrame> LogCameraFrames::frameAt(double t_s) {
  const auto after = std::upper_bound(stamps_s_.begin(), stamps_s_.end(), t_s);
  if (after == stamps_s_.begin()) return std::nullopt;
  const auto i = static_cast<std::size_t>(after - stamps_s_.begin()) - 1;
  if (cached_ && cached_->number == numbers_[i]) return cached_;
  reader_->seek(offsets_[i]);
  const std::optional<core::LogEvent> event = reader_->next();
  if (!event || event->channel != channel_) {
    CameraFrame frame;
    frame.t_s = stamps_s_[i];
    frame.number = numbers_[i];
    frame.error = log_path_ + ": the image event at byte " + std::to_string(offsets_[i]) +
                  " cannot be read again";
    cached_ = std::move(frame);
    return cached_;
  }
  cached_ = decodeCameraFrame(event->data.data(), event->data.size(), numbers_[i]);
  cached_->t_s = stamps_s_[i];
  return cached_;
}

std::string LogCameraFrames::describe() const {
  return std::filesystem::path(log_path_).filename().string() + " " + channel_;
}

RecentCameraFrames::RecentCameraFrames(std::string channel, std::size_t budget_bytes)
    : channel_(std::move(channel)), budget_bytes_(budget_bytes) {}

void RecentCameraFrames::add(const void* data, std::size_t size) {
  CameraFrame frame = decodeCameraFrame(data, size, received_++);
  if (!frame.error.empty() && frame.t_s == 0 && !frames_.empty()) {
    frame.t_s = frames_.back().t_s;
  }
  bytes_ += frame.pixels.total() * frame.pixels.elemSize();
  frames_.push_back(std::move(frame));
  while (frames_.size() > 1 && bytes_ > budget_bytes_) {
    bytes_ -= frames_.front().pixels.total() * frames_.front().pixels.elemSize();
    frames_.pop_front();
  }
}

std::optional<CameraFrame> RecentCameraFrames::frameAt(double t_s) {
  const auto after =
      std::upper_bound(frames_.begin(), frames_.end(), t_s,
                       [](double t, const CameraFrame& frame) { return t < frame.t_s; });
  if (after == frames_.begin()) return std::nullopt;
  return *std::prev(after);
}

std::string RecentCameraFrames::describe() const { return "live " + channel_; }

}  // namespace nadir::gui
