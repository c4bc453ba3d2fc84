#pragma once
// Where calibration images come from, one at a time: a folder of photographs,
// a camera channel of an LCM log, or the virtual checkerboard of a scenario.
// nadir calib and the nadir-calib window read them alike (the window adds a
// live channel).
//
// A source is used from one thread at a time: the virtual checkerboard's
// OpenGL context is made on the thread of the first next().

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "calib/board.h"
#include "render/camera_model.h"

namespace nadir::calib {

struct SourceFrame {
  cv::Mat gray;      // CV_8UC1
  std::string name;  // for the views' names: the file name, "CAMERA_DOWN #12", "virtual view 3"
  int number = 0;    // 0-based, in the order the source gave them (live: as received)
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;

  // The next image; nothing at the end (live: when no image came since the last
  // call). Throws std::runtime_error naming the source and the image when one
  // cannot be read or rendered.
  virtual std::optional<SourceFrame> next() = 0;
  // Whether next() may give more; a live source never ends.
  virtual bool ended() const = 0;
  // Images in all; -1 when unknown (live).
  virtual int count() const = 0;
  virtual bool live() const { return false; }
  // Where the images come from, for the window and messages: "folder DIR",
  // "log FILE channel CAMERA_DOWN", "live CAMERA_DOWN on udpm://...", "virtual
  // checkerboard (scenario calibration)".
  virtual std::string describe() const = 0;
  // The board the images show and the lens they were made with, when the source
  // knows them (the virtual checkerboard's).
  virtual std::optional<calib::BoardSpec> board() const { return std::nullopt; }
  virtual std::optional<render::CameraIntrinsics> trueLens() const { return std::nullopt; }
};

// The images of a folder (calib::imageFiles), sorted by name. Throws
// std::runtime_error naming the folder when it is not one or holds no image.
std::unique_ptr<FrameSource> openFolderSource(const std::string& folder);

// image_t on one channel of an LCM log, in the log's order. Throws
// core::LogError naming the log when it cannot be read, std::runtime_error
// naming the log and the channel when no message on it is an image.
std::unique_ptr<FrameSource> openLogSource(const std::string& log_path, const std::string& channel);

// The virtual checkerboard of a scenario (a built-in name or a YAML file, with
// "key=value" overrides): its views in order, its board the scenario's
// world.checkerboard (board()), its lens the scenario's camera (trueLens()).
// Throws core::ParamError for a bad scenario or override, std::invalid_argument
// when the scenario's world is not a checkerboard. The renderer is made by the
// first next() (on that thread; it throws render::GlContextError without EGL).
std::unique_ptr<FrameSource> openVirtualSource(const std::string& scenario,
                                               const std::vector<std::string>& overrides);

// image_t's and the renderer's pixels (grey, RGB or RGBA) as grey.
cv::Mat toGray(const cv::Mat& pixels);

}  // namespace nadir::calib
