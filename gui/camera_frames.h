#pragma once
// The camera images nadir-viewer shows beside its 3D view, without Qt: from a log
// (an index of the image events, each read when it is shown) or kept from a live
// bus (the newest ones, up to a memory budget).

#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace nadir::core {
class LcmLogReader;
}

namespace nadir::gui {

inline constexpr char kDefaultCameraChannel[] = "CAMERA_DOWN";

struct CameraFrame {
  double t_s = 0;           // the image's utime, s
  std::int64_t number = 0;  // 0-based, in the order the images came
  // CV_8UC1 or CV_8UC3 (R first); empty if the image_t does not decode, with
  // the reason in `error`.
  cv::Mat pixels;
  std::string error;
};

// Images that can be looked up by time.
class CameraFrames {
 public:
  virtual ~CameraFrames() = default;
  // The newest image stamped at or before t_s (absolute, s); nothing before the first.
  virtual std::optional<CameraFrame> frameAt(double t_s) = 0;
  virtual std::size_t count() const = 0;
  // Where the images come from, for captions ("run.lcmlog CAMERA_DOWN").
  virtual std::string describe() const = 0;
};

// image_t on one channel of an LCM log. The constructor reads the log once to
// index the image events (their stamps and offsets); frameAt() reads one event.
// Throws core::LogError naming the log if it cannot be opened.
class LogCameraFrames final : public CameraFrames {
 public:
  LogCameraFrames(const std::string& log_path, const std::string& channel = kDefaultCameraChannel);
  ~LogCameraFrames() override;

  std::optional<CameraFrame> frameAt(double t_s) override;
  std::size_t count() const override { return stamps_s_.size(); }
  std::string describe() const override;

 private:
  std::string log_path_;
  std::string channel_;
  std::unique_ptr<core::LcmLogReader> reader_;
  std::vector<double> stamps_s_;       // sorted
  std::vector<std::int64_t> offsets_;  // of the event of each stamp
  std::vector<std::int64_t> numbers_;  // arrival order of each stamp
  std::optional<CameraFrame> cached_;  // the frame shown last
};

// The newest images of a live stream: add() keeps each, dropping the oldest
// beyond budget_bytes of pixels (the newest one is always kept).
class RecentCameraFrames final : public CameraFrames {
 public:
  RecentCameraFrames(std::string channel, std::size_t budget_bytes);

  // Decodes an encoded image_t; a message that does not decode is kept as a
  // frame with the error (stamped at the last good stamp when its own is unknown).
  void add(const void* data, std::size_t size);

  std::optional<CameraFrame> frameAt(double t_s) override;
  std::size_t count() const override { return frames_.size(); }
  std::string describe() const override;
  std::int64_t received() const { return received_; }

 private:
  std::string channel_;
  std::size_t budget_bytes_;
  std::size_t bytes_ = 0;
  std::int64_t received_ = 0;
  std::deque<CameraFrame> frames_;  // by arrival, stamps assumed increasing
};

// An encoded image_t as a frame (pixels, or the reason it cannot be shown).
CameraFrame decodeCameraFrame(const void* data, std::size_t size, std::int64_t number);

}  // namespace nadir::gui
