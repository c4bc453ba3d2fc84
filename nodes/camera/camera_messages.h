#pragma once
// Conversions between the camera's structs and its LCM messages, in one place.

#include <cstdint>
#include <string>

#include <opencv2/core/mat.hpp>

#include "nadir/camera_info_t.hpp"
#include "nadir/image_t.hpp"
#include "nadir/pose_t.hpp"
#include "nodes/camera/camera_rig.h"

namespace nadir::camera {

// The rendered image as an image_t: GRAY or RGB raw, or MJPEG when jpeg_quality > 0.
nadir::image_t toImageMessage(const render::RenderedImage& rendered, int jpeg_quality);

// Pixels of an image_t: CV_8UC1 for GRAY, CV_8UC3 (R first) for RGB, BGR
// (converted) and MJPEG. Throws std::invalid_argument naming what is wrong
// (unsupported format, sizes that disagree, undecodable JPEG).
cv::Mat imageFromMessage(const nadir::image_t& message);

// T_world_body of a pose_t; throws std::invalid_argument for a non-finite
// position or a quaternion that is not a rotation.
Eigen::Isometry3d bodyPoseFromMessage(const nadir::pose_t& pose);

nadir::camera_info_t toCameraInfo(const std::string& name, const CameraSpec& spec,
                                  const render::CameraIntrinsics& intrinsics, std::int64_t utime);

}  // namespace nadir::camera
