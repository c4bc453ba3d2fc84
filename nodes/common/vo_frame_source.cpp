#include "nodes/common/vo_frame_source.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "lcmtypes/bus_io.h"

namespace nadir::nodes {

VoFrameSource::VoFrameSource(core::Bus& bus, const VoFrameSourceChannels& channels,
                             std::function<void(const Eigen::Isometry3d&)> on_start)
    : on_start_(std::move(on_start)),
      inputs_(bus, channels.range_channel, channels.attitude_channel) {
  subscriptions_.push_back(
      msg::subscribe<msg::Pose>(bus, channels.truth_channel, [this](const msg::Pose& pose) {
        if (started_) return;
        Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
        T_world_body.linear() = pose.q_world_body.toRotationMatrix();
        T_world_body.translation() = pose.p_ned_m;
        latest_truth_ = T_world_body;
      }));
  subscriptions_.push_back(msg::subscribe<msg::CameraInfo>(
      bus, channels.info_channel, [this](const msg::CameraInfo& info) {
        if (!info_ || info_->width != info.width || info_->height != info.height ||
            info_->fx != info.fx || info_->distortion.size() != info.distortion.size()) {
          undistort_map_x_.release();
        }
        info_ = info;
      }));
}

std::variant<vo::VoFrameInput, std::string> VoFrameSource::frame(const msg::Image& image,
                                                                 bool attitude_prior) {
  if (!info_ || (!started_ && !latest_truth_)) return std::string();
  const cv::Mat& pixels = image.pixels;
  if (pixels.cols != info_->width || pixels.rows != info_->height) {
    return "image " + std::to_string(pixels.cols) + "x" + std::to_string(pixels.rows) +
           " does not match camera_info_t's " + std::to_string(info_->width) + "x" +
           std::to_string(info_->height);
  }
  if (!started_) {
    // The vehicle's pose at this image, not at the truth's first message:
    // at 25 m/s a frame later is 0.8 m further.
    on_start_(*latest_truth_);
    started_ = true;
  }
  cv::Mat gray;
  if (pixels.channels() == 3) {
    cv::cvtColor(pixels, gray, cv::COLOR_RGB2GRAY);
  } else {
    gray = pixels;
  }
  const cv::Matx33d K(info_->fx, 0, info_->cx, 0, info_->fy, info_->cy, 0, 0, 1);
  if (info_->distorted()) {
    if (undistort_map_x_.empty()) {
      const std::vector<double> coefficients(info_->distortion.begin(), info_->distortion.end());
      cv::initUndistortRectifyMap(K, coefficients, cv::noArray(), K, gray.size(), CV_32FC1,
                                  undistort_map_x_, undistort_map_y_);
    }
    cv::Mat undistorted;
    cv::remap(gray, undistorted, undistort_map_x_, undistort_map_y_, cv::INTER_LINEAR);
    gray = undistorted;
  }
  vo::VoFrameInput input;
  input.utime = image.utime;
  input.gray = gray;
  input.K = K;
  input.R_body_cam = info_->q_body_cam.toRotationMatrix();
  input.readout_s = info_->readout_s;
  // The rangefinder looks along the body's down axis.
  input.range_m = inputs_.rangeAt_m(image.utime);
  input.range_ray_cam = input.R_body_cam.transpose() * Eigen::Vector3d::UnitZ();
  if (attitude_prior) input.q_world_body_prior = inputs_.attitudeAt(image.utime);
  return input;
}

}  // namespace nadir::nodes
