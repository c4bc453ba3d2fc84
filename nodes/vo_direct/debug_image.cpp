#include "nodes/vo_direct/debug_image.h"

#include <algorithm>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "nodes/common/status_line.h"

namespace nadir::vo {

cv::Mat drawDirectDebugImage(const cv::Mat& keyframe, const std::vector<DepthPixel>& points,
                             const std::string& status_text) {
  if (keyframe.empty() || keyframe.type() != CV_8UC1)
    throw std::invalid_argument("drawDirectDebugImage: expected an 8-bit gray key-frame");
  cv::Mat rgb;
  cv::cvtColor(keyframe, rgb, cv::COLOR_GRAY2RGB);
  if (!points.empty()) {
    // The colour scale spans the 2nd to 98th percentile of the inverse depths.
    std::vector<float> idepths;
    for (const DepthPixel& p : points) idepths.push_back(p.idepth);
    std::sort(idepths.begin(), idepths.end());
    const float lo = idepths[idepths.size() / 50];
    const float hi = idepths[idepths.size() - 1 - idepths.size() / 50];
    const float span = std::max(hi - lo, 1e-9f);
    cv::Mat scale(1, 256, CV_8UC1);
    for (int i = 0; i < 256; ++i) scale.at<unsigned char>(0, i) = static_cast<unsigned char>(i);
    cv::Mat colours;
    cv::applyColorMap(scale, colours, cv::COLORMAP_JET);  // BGR
    const int radius = std::max(1, rgb.cols / 640);
    for (const DepthPixel& p : points) {
      const int index = std::clamp(static_cast<int>(255.f * (p.idepth - lo) / span), 0, 255);
      const cv::Vec3b bgr = colours.at<cv::Vec3b>(0, index);
      cv::circle(rgb, cv::Point(cvRound(p.x), cvRound(p.y)), radius,
                 cv::Scalar(bgr[2], bgr[1], bgr[0]), cv::FILLED);
    }
  }
  nodes::drawStatusLine(rgb, status_text);
  return rgb;
}

}  // namespace nadir::vo
