#include "nodes/common/photometric.h"

#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "render/camera_model.h"

namespace nadir::vo {

void PhotometricCalibration::visit(core::ParamVisitor& v) {
  v.field("vignetting_corner", &vignetting_corner,
          {.doc = "the lens's light at the farthest image corner, share of the centre's (1: none)",
           .min = 0.01,
           .max = 1});
  v.field("response_gamma", &response_gamma,
          {.doc = "the camera's response, counts = 255 (linear / 255)^(1 / gamma) (1: linear)",
           .min = 0.1,
           .max = 10});
}

cv::Mat VignettingCorrection::apply(const cv::Mat& gray, const cv::Matx33d& K,
                                    const PhotometricCalibration& calibration) {
  if (gray.empty() || gray.type() != CV_8UC1)
    throw std::invalid_argument("VignettingCorrection: a frame must be 8-bit gray");
  if (calibration.flat()) return gray;
  if (gain_q8_.size() != gray.size() || K_ != K ||
      calibration_.vignetting_corner != calibration.vignetting_corner ||
      calibration_.response_gamma != calibration.response_gamma) {
    render::CameraIntrinsics intrinsics;
    intrinsics.width = gray.cols;
    intrinsics.height = gray.rows;
    intrinsics.fx = K(0, 0);
    intrinsics.fy = K(1, 1);
    intrinsics.cx = K(0, 2);
    intrinsics.cy = K(1, 2);
    const double k = render::vignettingK(calibration.vignetting_corner, intrinsics);
    gain_q8_.create(gray.size(), CV_16UC1);
    for (int v = 0; v < gray.rows; ++v) {
      auto* row = gain_q8_.ptr<std::uint16_t>(v);
      const double y = (v - intrinsics.cy) / intrinsics.fy;
      for (int u = 0; u < gray.cols; ++u) {
        const double x = (u - intrinsics.cx) / intrinsics.fx;
        const double gain =
            std::pow(render::vignettingAt(k, x, y), -1.0 / calibration.response_gamma);
        row[u] = static_cast<std::uint16_t>(std::lround(256.0 * gain));
      }
    }
    K_ = K;
    calibration_ = calibration;
  }
  cv::Mat out(gray.size(), CV_8UC1);
  for (int v = 0; v < gray.rows; ++v) {
    const std::uint8_t* in = gray.ptr<std::uint8_t>(v);
    const std::uint16_t* gain = gain_q8_.ptr<std::uint16_t>(v);
    std::uint8_t* o = out.ptr<std::uint8_t>(v);
    for (int u = 0; u < gray.cols; ++u) {
      const std::uint32_t value = (static_cast<std::uint32_t>(in[u]) * gain[u] + 128u) >> 8;
      o[u] = static_cast<std::uint8_t>(value > 255u ? 255u : value);
    }
  }
  return out;
}

}  // namespace nadir::vo
