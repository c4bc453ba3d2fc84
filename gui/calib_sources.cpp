#include "gui/calib_sources.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <iterator>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <utility>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/bus.h"
#include "lcmtypes/bus_io.h"
#include "lcmtypes/codec.h"
#include "lcmtypes/image.h"

namespace nadir::gui {
namespace {

class LiveSource final : public FrameSource {
 public:
  explicit LiveSource(const LiveSourceParams& params) : channel_(params.channel) {
    core::BusParams bus_params;
    bus_params.url = params.bus_url;
    bus_params.recv_buf_size_bytes = params.recv_buf_bytes;
    bus_ = core::openBus(bus_params);
    subscription_ = msg::subscribe<msg::Image>(*bus_, channel_, [this](const msg::Image& image) {
      const std::lock_guard lock(mutex_);
      newest_ = image.pixels;
      ++received_;
    });
    drainer_ = std::thread([this] {
      try {
        while (!stop_) bus_->handle(std::chrono::milliseconds(100));
      } catch (...) {
        const std::lock_guard lock(mutex_);
        failure_ = std::current_exception();
      }
    });
  }
  ~LiveSource() override {
    stop_ = true;
    drainer_.join();
  }

  std::optional<SourceFrame> next() override {
    const std::lock_guard lock(mutex_);
    if (failure_) std::rethrow_exception(failure_);
    if (received_ == given_ || newest_.empty()) return std::nullopt;
    given_ = received_;
    const int number = static_cast<int>(received_ - 1);
    return SourceFrame{calib::toGray(newest_), channel_ + " #" + std::to_string(number), number};
  }
  bool ended() const override { return false; }
  int count() const override { return -1; }
  bool live() const override { return true; }
  std::string describe() const override { return "live " + channel_ + " on " + bus_->url(); }

 private:
  std::string channel_;
  std::unique_ptr<core::Bus> bus_;
  core::Subscription subscription_;
  std::mutex mutex_;  // what the drainer fills, against next()
  cv::Mat newest_;
  std::int64_t received_ = 0;
  std::int64_t given_ = 0;
  std::exception_ptr failure_;
  std::atomic<bool> stop_{false};
  std::thread drainer_;
};

}  // namespace

std::unique_ptr<FrameSource> openLiveSource(const LiveSourceParams& params) {
  return std::make_unique<LiveSource>(params);
}

cv::Mat drawDetection(const cv::Mat& gray, const std::optional<calib::Detection>& detection,
                      const calib::BoardSpec& board) {
  cv::Mat rgb;
  cv::cvtColor(gray, rgb, gray.channels() == 1 ? cv::COLOR_GRAY2RGB : cv::COLOR_BGR2RGB);
  // Lines of 1 px on a 640 px image, wider on larger ones.
  const int scale = std::max(1, static_cast<int>(std::lround(rgb.cols / 640.0)));
  if (!detection) {
    cv::rectangle(rgb, cv::Rect(0, 0, rgb.cols, rgb.rows), cv::Scalar(255, 0, 0), 6 * scale);
    return rgb;
  }
  // cv::drawChessboardCorners' row colours (its table is BGR; these are RGB).
  static const cv::Scalar kRowColours[] = {{255, 0, 0},   {255, 128, 0}, {200, 200, 0}, {0, 255, 0},
                                           {0, 200, 200}, {0, 0, 255},   {255, 0, 255}};
  constexpr int kColours = static_cast<int>(std::size(kRowColours));
  const int radius = 4 * scale;
  const std::vector<cv::Point2f>& corners = detection->corners_px;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const int row = static_cast<int>(i) / board.inner_cols;
    const cv::Scalar& colour = kRowColours[row % kColours];
    const cv::Point2f& p = corners[i];
    const float r = static_cast<float>(radius);
    cv::line(rgb, p + cv::Point2f(-r, -r), p + cv::Point2f(r, r), colour, scale, cv::LINE_AA);
    cv::line(rgb, p + cv::Point2f(-r, r), p + cv::Point2f(r, -r), colour, scale, cv::LINE_AA);
    cv::circle(rgb, p, radius + scale, colour, scale, cv::LINE_AA);
    if (i > 0) cv::line(rgb, corners[i - 1], p, colour, scale, cv::LINE_AA);
  }
  return rgb;
}

Undistorter::Undistorter(const calib::Calibration& calibration) : size_(calibration.image_size) {
  const cv::Mat camera_matrix(calibration.camera_matrix);
  const cv::Mat distortion(calibration.distortion);
  if (calibration.model == calib::LensModel::kFisheye) {
    cv::fisheye::initUndistortRectifyMap(camera_matrix, distortion, cv::Matx33d::eye(),
                                         camera_matrix, size_, CV_16SC2, map1_, map2_);
  } else {
    cv::initUndistortRectifyMap(camera_matrix, distortion, cv::noArray(), camera_matrix, size_,
                                CV_16SC2, map1_, map2_);
  }
}

cv::Mat Undistorter::undistort(const cv::Mat& image) const {
  if (image.size() != size_) return image;
  cv::Mat undistorted;
  cv::remap(image, undistorted, map1_, map2_, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  return undistorted;
}

}  // namespace nadir::gui
