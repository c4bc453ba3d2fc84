#pragma once
// The nadir-calib window's work that needs no Qt: where its images come from (a
// folder, an LCM log, a live channel, the virtual checkerboard) and the images it
// shows (the detected corners drawn, the image undistorted).
//
// A source is used from one thread at a time (the window's worker): the virtual
// checkerboard's OpenGL context is made on the thread of the first next().

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "calib/board.h"
#include "calib/calibrate.h"
#include "calib/sources/frame_sources.h"
#include "render/camera_model.h"

namespace nadir::gui {

using calib::FrameSource;
using calib::openFolderSource;
using calib::openLogSource;
using calib::openVirtualSource;
using calib::SourceFrame;

struct LiveSourceParams {
  std::string channel = "CAMERA_DOWN";
  std::string bus_url;  // empty: $LCM_DEFAULT_URL, else LCM's
  // Room for a few 1.2 MB images (the kernel caps it at net.core.rmem_max).
  std::int64_t recv_buf_bytes = std::int64_t{8} << 20;
};

// The newest image_t on a channel of a live bus, drained on a thread of its own:
// images that come while the window looks at one are dropped, only the newest is
// kept. Throws core::BusError when the bus cannot be opened.
std::unique_ptr<FrameSource> openLiveSource(const LiveSourceParams& params);

// The image in RGB with the detected corners drawn as cv::drawChessboardCorners
// draws them (each row of the board in its colour, joined in order), lines and
// circles thick enough to stay visible when a large image is shown small; without
// a detection a red frame around it says that no board was found.
cv::Mat drawDetection(const cv::Mat& gray, const std::optional<calib::Detection>& detection,
                      const calib::BoardSpec& board);

// Remaps images of the calibrated camera to a pinhole without distortion with the
// same camera matrix (cv::initUndistortRectifyMap, or cv::fisheye's for the
// fisheye model); the maps are made once.
class Undistorter {
 public:
  explicit Undistorter(const calib::Calibration& calibration);
  // An image of the calibration's size, undistorted; an image of another size is
  // returned as it is.
  cv::Mat undistort(const cv::Mat& image) const;

 private:
  cv::Size size_;
  cv::Mat map1_;
  cv::Mat map2_;
};

}  // namespace nadir::gui
