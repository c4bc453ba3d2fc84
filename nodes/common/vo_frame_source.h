#pragma once
// What every monocular VO node does with the bus before its VO sees a frame:
// the start pose (the truth's pose at the first image: the newest received
// before it), the lens (camera_info_t),
// the rangefinder and the flight controller's attitude, and each image turned
// into a VoFrameInput: gray, undistorted, with the range along the body's down
// axis. The node adapters of the feature VO and the direct VO share it.

#include <functional>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "core/bus.h"
#include "lcmtypes/image.h"
#include "lcmtypes/messages.h"
#include "nodes/common/flight_inputs.h"
#include "nodes/common/vo_frame.h"

namespace nadir::nodes {

struct VoFrameSourceChannels {
  std::string info_channel;
  std::string range_channel;
  std::string attitude_channel;
  std::string truth_channel;
};

class VoFrameSource {
 public:
  // on_start: the truth's pose (T_world_body) at the first image that can be
  // a frame, once, before that frame is returned.
  VoFrameSource(core::Bus& bus, const VoFrameSourceChannels& channels,
                std::function<void(const Eigen::Isometry3d&)> on_start);

  // The frame for an image; or why it cannot be one (its size does not match
  // camera_info_t's); or an empty string while the lens or the truth has not
  // come yet. attitude_prior: take the flight controller's attitude at the
  // image's time.
  std::variant<vo::VoFrameInput, std::string> frame(const msg::Image& image, bool attitude_prior);

 private:
  std::optional<msg::CameraInfo> info_;
  std::optional<Eigen::Isometry3d> latest_truth_;  // until the start
  bool started_ = false;
  std::function<void(const Eigen::Isometry3d&)> on_start_;
  FlightInputs inputs_;
  cv::Mat undistort_map_x_, undistort_map_y_;
  std::vector<core::Subscription> subscriptions_;
};

// The status of a vo_estimate_t.
inline msg::VoStatus wireStatus(vo::VoStatus status) {
  return status == vo::VoStatus::kTracking ? msg::VoStatus::TRACKING
         : status == vo::VoStatus::kLost   ? msg::VoStatus::LOST
                                           : msg::VoStatus::INITIALIZING;
}
inline const char* statusName(vo::VoStatus status) {
  return status == vo::VoStatus::kTracking ? "TRACKING"
         : status == vo::VoStatus::kLost   ? "LOST"
                                           : "INITIALIZING";
}

}  // namespace nadir::nodes
