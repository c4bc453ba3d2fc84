#include "nodes/vo_feature/vo_feature_node.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <sstream>

#include "core/frames.h"
#include "lcmtypes/bus_io.h"

namespace nadir::vo {
void VoFeatureNodeParams::visit(core::ParamVisitor& v) {
  v.field("enabled", &enabled, {.doc = "run the feature VO in this scenario"});
  v.field("image_channel", &image_channel, {.doc = "the camera's images (gray or RGB)"});
  v.field("info_channel", &info_channel, {.doc = "its camera_info_t (intrinsics, mount)"});
  v.field("range_channel", &range_channel,
          {.doc = "range_t: the rangefinder along the body's down axis, for the scale"});
  v.field("attitude_channel", &attitude_channel,
          {.doc = "attitude_t: the flight controller's attitude (for attitude_prior)"});
  v.field("truth_channel", &truth_channel, {.doc = "pose_t read once: the start pose"});
  v.field("pose_channel", &pose_channel, {.doc = "vo_estimate_t out"});
  v.field("debug_channel", &debug_channel,
          {.doc = "image_t out: the frame with the tracked features (thesis figure 21)"});
  v.field("command_channel", &command_channel,
          {.doc = "vo_command_t in: resets for vo_feature or for every VO node"});
  v.field("debug_every_frames", &debug_every_frames,
          {.doc = "a debug image every this many frames (0: none)", .min = 0, .max = 1000000});
  v.field("debug_jpeg_quality", &debug_jpeg_quality,
          {.doc = "JPEG quality of the debug image", .min = 1, .max = 100});
  v.field("attitude_prior", &attitude_prior,
          {.doc = "use the flight controller's attitude as each frame's rotation prior"});
  v.field("wall_clock_timing", &wall_clock_timing,
          {.doc = "publish wall-clock processing time (0 keeps runs byte-identical)"});
  core::visitGroup(v, "vo", "the visual odometry", vo);
}

VoFeatureNode::VoFeatureNode(core::Bus& bus, const VoFeatureNodeParams& params)
    : bus_(bus),
      params_(params),
      vo_(params.vo),
      inputs_(bus, params.range_channel, params.attitude_channel),
      commands_(
          bus, params.command_channel, kFeatureSourceName,
          [this](const nodes::VoResetRequest& request) { pending_resets_.push_back(request); }) {
  subscriptions_.push_back(
      msg::subscribe<msg::Pose>(bus_, params_.truth_channel, [this](const msg::Pose& pose) {
        if (started_) return;
        Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
        T_world_body.linear() = pose.q_world_body.toRotationMatrix();
        T_world_body.translation() = pose.p_ned_m;
        vo_.setStartPose(T_world_body);
        started_ = true;
      }));
  subscriptions_.push_back(msg::subscribe<msg::CameraInfo>(
      bus_, params_.info_channel, [this](const msg::CameraInfo& info) {
        if (!info_ || info_->width != info.width || info_->height != info.height ||
            info_->fx != info.fx || info_->distortion.size() != info.distortion.size()) {
          undistort_map_x_.release();
        }
        info_ = info;
      }));
  subscriptions_.push_back(msg::subscribe<msg::Image>(
      bus_, params_.image_channel, [this](const msg::Image& image) { onImage(image); },
      [this](const std::string& reason) { drop(reason); }));
}

void VoFeatureNode::drop(const std::string& reason) {
  if (dropped_images_++ == 0) first_drop_reason_ = reason;
}

void VoFeatureNode::applyResets() {
  for (const nodes::VoResetRequest& request : pending_resets_) {
    vo_.restart(request.T_world_body);
    // A pose given stands for the start pose the truth would give.
    if (request.T_world_body) started_ = true;
  }
  pending_resets_.clear();
}

void VoFeatureNode::onImage(const msg::Image& image) {
  applyResets();
  if (!info_ || !started_) return;  // the lens and the start pose come first
  const cv::Mat& frame = image.pixels;
  if (frame.cols != info_->width || frame.rows != info_->height) {
    drop("image " + std::to_string(frame.cols) + "x" + std::to_string(frame.rows) +
         " does not match camera_info_t's " + std::to_string(info_->width) + "x" +
         std::to_string(info_->height));
    return;
  }
  cv::Mat gray;
  if (frame.channels() == 3) {
    cv::cvtColor(frame, gray, cv::COLOR_RGB2GRAY);
  } else {
    gray = frame;
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

  const std::optional<Eigen::Quaterniond> attitude = inputs_.attitudeAt(image.utime);
  VoFrameInput input;
  input.utime = image.utime;
  input.gray = gray;
  input.K = K;
  input.R_body_cam = info_->q_body_cam.toRotationMatrix();
  // The rangefinder looks along the body's down axis.
  input.range_m = inputs_.validRange_m();
  input.range_ray_cam = input.R_body_cam.transpose() * Eigen::Vector3d::UnitZ();
  if (params_.attitude_prior) input.q_world_body_prior = attitude;

  const auto started = std::chrono::steady_clock::now();
  const VoFrameOutput out = vo_.process(input);
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  processing_s_ += elapsed_s;
  ++frames_;

  msg::VoEstimate estimate;
  estimate.utime = image.utime;
  estimate.source = kFeatureSourceName;
  estimate.status = out.status == VoStatus::kTracking ? msg::VoStatus::TRACKING
                    : out.status == VoStatus::kLost   ? msg::VoStatus::LOST
                                                      : msg::VoStatus::INITIALIZING;
  estimate.p_ned_m = out.T_world_body.translation();
  estimate.q_world_body = Eigen::Quaterniond(out.T_world_body.rotation());
  estimate.num_features = out.tracked_points;
  estimate.num_resets = out.resets;
  estimate.processing_time_s = params_.wall_clock_timing ? elapsed_s : 0.0;
  msg::publish(bus_, params_.pose_channel, estimate);
  if (params_.debug_every_frames > 0 &&
      (frames_ - 1) % static_cast<std::uint64_t>(params_.debug_every_frames) == 0)
    publishDebugImage(gray, image.utime, out);
}

void VoFeatureNode::publishDebugImage(const cv::Mat& frame, std::int64_t utime,
                                      const VoFrameOutput& out) {
  const char* status = out.status == VoStatus::kTracking ? "TRACKING"
                       : out.status == VoStatus::kLost   ? "LOST"
                                                         : "INITIALIZING";
  const std::vector<DebugFeature>& features = vo_.lastFrameFeatures();
  std::ostringstream text;
  text << status << "  " << out.tracked_points << " matched of " << features.size()
       << " features  map " << vo_.numMapPoints() << " points  key-frames "
       << vo_.timing().keyframes << "  resets " << out.resets;
  msg::publish(
      bus_, params_.debug_channel,
      msg::Image{
          utime, drawDebugImage(frame, features, text.str()), params_.debug_jpeg_quality, {}});
}

}  // namespace nadir::vo
