#include "calib/sources/frame_sources.h"

#include <filesystem>
#include <set>
#include <stdexcept>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "calib/image_folder.h"
#include "calib/virtual/virtual_board.h"
#include "core/lcm_log.h"
#include "lcmtypes/codec.h"
#include "lcmtypes/image.h"
#include "nodes/scenario.h"

namespace nadir::calib {
namespace {

namespace fs = std::filesystem;

class FolderSource final : public FrameSource {
 public:
  explicit FolderSource(const std::string& folder) : folder_(folder), files_(imageFiles(folder)) {}

  std::optional<SourceFrame> next() override {
    if (ended()) return std::nullopt;
    const int number = next_++;
    const std::string& path = files_[static_cast<std::size_t>(number)];
    SourceFrame frame{readGrayImage(path), fs::path(path).filename().string(), number};
    if (frame.gray.empty()) throw std::runtime_error(path + ": cannot be read as an image");
    return frame;
  }
  bool ended() const override { return next_ >= count(); }
  int count() const override { return static_cast<int>(files_.size()); }
  std::string describe() const override { return "folder " + folder_; }

 private:
  std::string folder_;
  std::vector<std::string> files_;
  int next_ = 0;
};

class LogSource final : public FrameSource {
 public:
  LogSource(const std::string& log_path, const std::string& channel)
      : log_path_(log_path), channel_(channel), reader_(log_path) {
    // Indexed first, so that the window can say "image 3 of 40" and a log
    // without the channel is refused at once.
    std::set<std::string> channels;
    while (const std::optional<core::LogEvent> event = reader_.next()) {
      channels.insert(event->channel);
      if (event->channel == channel_) offsets_.push_back(event->offset);
    }
    if (offsets_.empty()) {
      std::string seen;
      for (const std::string& name : channels) seen += (seen.empty() ? "" : ", ") + name;
      throw std::runtime_error(log_path_ + ": no message on channel " + channel_ +
                               (seen.empty() ? " (the log is empty)" : " (it has " + seen + ")"));
    }
  }

  std::optional<SourceFrame> next() override {
    if (ended()) return std::nullopt;
    const int number = next_++;
    const std::string name = channel_ + " #" + std::to_string(number);
    reader_.seek(offsets_[static_cast<std::size_t>(number)]);
    const std::optional<core::LogEvent> event = reader_.next();
    if (!event || event->channel != channel_) {
      throw std::runtime_error(log_path_ + ": " + name + " cannot be read again");
    }
    try {
      const msg::Image image = msg::decode<msg::Image>(event->data.data(), event->data.size());
      return SourceFrame{toGray(image.pixels), name, number};
    } catch (const std::exception& error) {
      throw std::runtime_error(log_path_ + ": " + name + " is not an image_t: " + error.what());
    }
  }
  bool ended() const override { return next_ >= count(); }
  int count() const override { return static_cast<int>(offsets_.size()); }
  std::string describe() const override { return "log " + log_path_ + " channel " + channel_; }

 private:
  std::string log_path_;
  std::string channel_;
  core::LcmLogReader reader_;
  std::vector<std::int64_t> offsets_;
  int next_ = 0;
};

class VirtualSource final : public FrameSource {
 public:
  VirtualSource(const std::string& scenario, const std::vector<std::string>& overrides)
      : scenario_name_(scenario), scenario_(nodes::loadScenario(scenario, overrides)) {
    if (scenario_.world.kind != "checkerboard") {
      throw std::invalid_argument("scenario " + scenario + " has world.kind " +
                                  scenario_.world.kind +
                                  ", not checkerboard: the virtual checkerboard needs a board "
                                  "(try --virtual calibration)");
    }
    const terrain::CheckerboardParams& board = scenario_.world.checkerboard;
    board_ = BoardSpec{board.inner_cols, board.inner_rows, board.square_m};
    validateBoard(board_);
    true_lens_ = scenario_.camera.camera.intrinsics();
  }

  std::optional<SourceFrame> next() override {
    if (ended()) return std::nullopt;
    if (!checkerboard_) {
      checkerboard_ = std::make_unique<VirtualCheckerboard>(
          scenario_.world.checkerboard, scenario_.camera.camera, scenario_.calibration);
    }
    const int number = next_++;
    return SourceFrame{toGray(checkerboard_->render(number).image),
                       "virtual view " + std::to_string(number), number};
  }
  bool ended() const override { return next_ >= (checkerboard_ ? checkerboard_->size() : count()); }
  int count() const override { return scenario_.calibration.views; }
  std::string describe() const override {
    return "virtual checkerboard (scenario " + scenario_name_ + ")";
  }
  std::optional<BoardSpec> board() const override { return board_; }
  std::optional<render::CameraIntrinsics> trueLens() const override { return true_lens_; }

 private:
  std::string scenario_name_;
  nodes::ScenarioParams scenario_;
  BoardSpec board_;
  render::CameraIntrinsics true_lens_;
  std::unique_ptr<VirtualCheckerboard> checkerboard_;
  int next_ = 0;
};

}  // namespace

std::unique_ptr<FrameSource> openFolderSource(const std::string& folder) {
  return std::make_unique<FolderSource>(folder);
}

std::unique_ptr<FrameSource> openLogSource(const std::string& log_path,
                                           const std::string& channel) {
  return std::make_unique<LogSource>(log_path, channel);
}

std::unique_ptr<FrameSource> openVirtualSource(const std::string& scenario,
                                               const std::vector<std::string>& overrides) {
  return std::make_unique<VirtualSource>(scenario, overrides);
}

cv::Mat toGray(const cv::Mat& pixels) {
  if (pixels.channels() == 1) return pixels;
  cv::Mat gray;
  cv::cvtColor(pixels, gray, pixels.channels() == 4 ? cv::COLOR_RGBA2GRAY : cv::COLOR_RGB2GRAY);
  return gray;
}

}  // namespace nadir::calib
