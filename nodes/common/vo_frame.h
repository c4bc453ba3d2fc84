#pragma once
// What every monocular VO core takes for one camera frame and the states it
// reports: plain structs, no LCM. The node adapters fill VoFrameInput from the
// bus (nodes/common/vo_frame_source.h).

#include <cstdint>
#include <optional>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

namespace nadir::vo {

struct VoFrameInput {
  std::int64_t utime = 0;
  cv::Mat gray;  // 8-bit, undistorted
  cv::Matx33d K = cv::Matx33d::eye();
  Eigen::Matrix3d R_body_cam = Eigen::Matrix3d::Identity();
  // The rangefinder, for the metric scale: its range along its ray (a unit
  // vector in the camera frame), m.
  std::optional<double> range_m;
  Eigen::Vector3d range_ray_cam = Eigen::Vector3d::UnitZ();
  std::optional<Eigen::Quaterniond> q_world_body_prior;  // optional attitude prior
  // A rolling shutter's readout, top row to bottom row, s (0: a global shutter).
  double readout_s = 0.0;
};

enum class VoStatus { kInitializing, kTracking, kLost };

}  // namespace nadir::vo
