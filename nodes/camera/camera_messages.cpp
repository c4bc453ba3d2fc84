#include "nodes/camera/camera_messages.h"

#include <cmath>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/frames.h"

namespace nadir::camera {

nadir::image_t toImageMessage(const render::RenderedImage& rendered, int jpeg_quality) {
  const cv::Mat& pixels = rendered.image;
  const bool gray = pixels.channels() == 1;
  nadir::image_t message{};
  message.utime = rendered.utime;
  message.width = pixels.cols;
  message.height = pixels.rows;
  if (jpeg_quality > 0) {
    cv::Mat bgr;
    if (!gray) cv::cvtColor(pixels, bgr, cv::COLOR_RGB2BGR);
    std::vector<std::uint8_t> jpeg;
    cv::imencode(".jpg", gray ? pixels : bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, jpeg_quality});
    message.row_stride = 0;
    message.pixelformat = nadir::image_t::PIXEL_FORMAT_MJPEG;
    message.data = std::move(jpeg);
  } else {
    message.row_stride = pixels.cols * pixels.channels();
    message.pixelformat = gray ? std::int32_t{nadir::image_t::PIXEL_FORMAT_GRAY}
                               : std::int32_t{nadir::image_t::PIXEL_FORMAT_RGB};
    const cv::Mat continuous = pixels.isContinuous() ? pixels : pixels.clone();
    message.data.assign(continuous.data,
                        continuous.data + continuous.total() * continuous.elemSize());
  }
  message.size = static_cast<std::int32_t>(message.data.size());
  message.nmetadata = 0;
  return message;
}

cv::Mat imageFromMessage(const nadir::image_t& message) {
  const auto fail = [&](const std::string& what) {
    return std::invalid_argument("image_t " + std::to_string(message.width) + "x" +
                                 std::to_string(message.height) + " at utime " +
                                 std::to_string(message.utime) + ": " + what);
  };
  if (message.size != static_cast<std::int32_t>(message.data.size())) {
    throw fail("size field " + std::to_string(message.size) + " but " +
               std::to_string(message.data.size()) + " bytes of data");
  }
  if (message.width <= 0 || message.height <= 0) throw fail("no pixels");
  if (message.pixelformat == nadir::image_t::PIXEL_FORMAT_MJPEG) {
    cv::Mat decoded = cv::imdecode(message.data, cv::IMREAD_UNCHANGED);
    if (decoded.empty()) throw fail("JPEG data does not decode");
    if (decoded.cols != message.width || decoded.rows != message.height) {
      throw fail("JPEG is " + std::to_string(decoded.cols) + "x" + std::to_string(decoded.rows));
    }
    if (decoded.channels() == 3) cv::cvtColor(decoded, decoded, cv::COLOR_BGR2RGB);
    return decoded;
  }
  int channels = 0;
  switch (message.pixelformat) {
    case nadir::image_t::PIXEL_FORMAT_GRAY:
      channels = 1;
      break;
    case nadir::image_t::PIXEL_FORMAT_RGB:
    case nadir::image_t::PIXEL_FORMAT_BGR:
      channels = 3;
      break;
    default:
      throw fail("unsupported pixel format " + std::to_string(message.pixelformat));
  }
  if (message.row_stride < message.width * channels ||
      static_cast<std::int64_t>(message.row_stride) * message.height > message.size) {
    throw fail("row stride " + std::to_string(message.row_stride) + " does not fit " +
               std::to_string(message.size) + " bytes");
  }
  const cv::Mat view(message.height, message.width, channels == 1 ? CV_8UC1 : CV_8UC3,
                     const_cast<std::uint8_t*>(message.data.data()),
                     static_cast<std::size_t>(message.row_stride));
  cv::Mat pixels = view.clone();
  if (message.pixelformat == nadir::image_t::PIXEL_FORMAT_BGR)
    cv::cvtColor(pixels, pixels, cv::COLOR_BGR2RGB);
  return pixels;
}

Eigen::Isometry3d bodyPoseFromMessage(const nadir::pose_t& pose) {
  for (double p : pose.pos) {
    if (!std::isfinite(p))
      throw std::invalid_argument("pose_t at utime " + std::to_string(pose.utime) +
                                  " has a non-finite position");
  }
  Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
  T_world_body.linear() = core::quaternionFromWire(pose.orientation).toRotationMatrix();
  T_world_body.translation() = Eigen::Vector3d(pose.pos[0], pose.pos[1], pose.pos[2]);
  return T_world_body;
}

nadir::camera_info_t toCameraInfo(const std::string& name, const CameraSpec& spec,
                                  const render::CameraIntrinsics& intrinsics, std::int64_t utime) {
  nadir::camera_info_t info{};
  info.utime = utime;
  info.camera_name = name;
  info.width = intrinsics.width;
  info.height = intrinsics.height;
  info.fx = intrinsics.fx;
  info.fy = intrinsics.fy;
  info.cx = intrinsics.cx;
  info.cy = intrinsics.cy;
  info.distortion_model = intrinsics.hasDistortion()
                              ? std::int8_t{nadir::camera_info_t::DISTORTION_RADTAN}
                              : std::int8_t{nadir::camera_info_t::DISTORTION_NONE};
  info.distortion.assign(intrinsics.distortion.begin(), intrinsics.distortion.end());
  info.num_distortion = static_cast<std::int32_t>(info.distortion.size());
  info.fps = spec.fps;
  const Eigen::Isometry3d T_body_cam = spec.T_body_cam();
  for (int i = 0; i < 3; ++i) info.position_cam_in_body_m[i] = T_body_cam.translation()[i];
  core::quaternionToWire(Eigen::Quaterniond(T_body_cam.rotation()), info.orientation_body_cam);
  return info;
}

}  // namespace nadir::camera
