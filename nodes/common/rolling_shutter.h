#pragma once
// Rolling-shutter rectification: a rolling-shutter camera reads row v at
// t_v = (v - v_mid) / rows * readout_s from the frame's stamp (the middle
// row); moving with angular velocity omega and velocity v (camera frame),
// every row sees from another pose. The frame is warped to what a global
// shutter at the stamp would have seen, under constant velocity and with the
// scene at depth_m along the optical axis (the rangefinder's ground: the
// translation's part is small beside the rotation's at altitude).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/matx.hpp>

namespace nadir::vo {

struct CameraTwist {
  Eigen::Vector3d omega_cam_rps = Eigen::Vector3d::Zero();  // angular velocity, camera frame
  Eigen::Vector3d v_cam_mps = Eigen::Vector3d::Zero();      // velocity, camera frame
};

// The constant twist that moves a camera by T_prev_cur (the frame's pose in
// the previous frame's camera axes, T_world_cam(k-1)^-1 T_world_cam(k)) in dt_s.
CameraTwist cameraTwist(const Eigen::Isometry3d& T_prev_cur, double dt_s);

// gray: 8-bit, undistorted, intrinsics K. Throws std::invalid_argument on a
// bad image or a non-positive depth.
cv::Mat rectifyRollingShutter(const cv::Mat& gray, const cv::Matx33d& K, double readout_s,
                              const CameraTwist& twist, double depth_m);

}  // namespace nadir::vo
