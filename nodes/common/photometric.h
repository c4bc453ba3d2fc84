#pragma once
// The camera's photometric calibration as a VO is given it, the way DSO is
// given a lens's vignette and response (Engel et al. 2018): the vignetting of
// render/camera_model.h, V = 1 / (1 + k r^2)^2, and the response, counts =
// 255 (linear / 255)^(1 / response_gamma). A frame is divided by the
// vignetting as the response saw it, I / V^(1 / gamma): exposure changes stay
// a gain on the result, which both VOs already follow, and dark pixels keep
// their resolution (the response itself is not undone).

#include <opencv2/core/mat.hpp>
#include <opencv2/core/matx.hpp>

#include "core/params.h"

namespace nadir::vo {

struct PhotometricCalibration {
  // The lens's light at the image corner farthest from the principal point,
  // a share of the centre's; 1: no vignetting.
  double vignetting_corner = 1.0;
  // The response's gamma; 1: linear.
  double response_gamma = 1.0;

  void visit(core::ParamVisitor& v);
  bool flat() const { return !(vignetting_corner < 1.0); }
};

// Divides frames by the vignetting; the gain map is made once per image size,
// intrinsics and calibration.
class VignettingCorrection {
 public:
  // gray: 8-bit, undistorted, intrinsics K. Returns gray itself when the
  // calibration is flat; saturates at 255. Throws std::invalid_argument on an
  // image that is not 8-bit gray.
  cv::Mat apply(const cv::Mat& gray, const cv::Matx33d& K,
                const PhotometricCalibration& calibration);

 private:
  cv::Mat gain_q8_;  // CV_16U: 256 / V^(1 / gamma) per pixel
  cv::Matx33d K_;
  PhotometricCalibration calibration_;
};

}  // namespace nadir::vo
