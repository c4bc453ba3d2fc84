#include "nodes/vo_feature/debug_image.h"

#include <opencv2/imgproc.hpp>

#include "nodes/common/status_line.h"

#include <stdexcept>

namespace nadir::vo {

cv::Mat drawDebugImage(const cv::Mat& frame, const std::vector<DebugFeature>& features,
                       const std::string& status_text) {
  if (frame.empty() || frame.depth() != CV_8U || (frame.channels() != 1 && frame.channels() != 3))
    throw std::invalid_argument("drawDebugImage: expected an 8-bit grey or RGB frame");
  cv::Mat rgb;
  if (frame.channels() == 1) {
    cv::cvtColor(frame, rgb, cv::COLOR_GRAY2RGB);
  } else {
    rgb = frame.clone();
  }
  const cv::Scalar green(0, 255, 0);
  const cv::Scalar blue(60, 140, 255);
  // Sizes follow the image so that a 1280 px frame shaded down still shows them.
  const int half_box = std::max(2, rgb.cols / 320);
  for (const DebugFeature& f : features) {
    const cv::Point c(cvRound(f.px.x), cvRound(f.px.y));
    if (f.tracked) {
      cv::rectangle(rgb, c - cv::Point(half_box, half_box), c + cv::Point(half_box, half_box),
                    green, 1, cv::LINE_AA);
      cv::circle(rgb, c, 1, green, cv::FILLED);
    } else {
      cv::circle(rgb, c, 1, blue, cv::FILLED);
    }
  }
  nodes::drawStatusLine(rgb, status_text);
  return rgb;
}

}  // namespace nadir::vo
