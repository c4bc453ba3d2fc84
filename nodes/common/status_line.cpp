#include "nodes/common/status_line.h"

#include <algorithm>

#include <opencv2/imgproc.hpp>

namespace nadir::nodes {

void drawStatusLine(cv::Mat& rgb, const std::string& text) {
  const double font_scale = std::max(0.4, rgb.cols / 1600.0);
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, font_scale, 1, &baseline);
  cv::rectangle(rgb, cv::Point(0, 0), cv::Point(size.width + 12, size.height + baseline + 10),
                cv::Scalar(0, 0, 0), cv::FILLED);
  cv::putText(rgb, text, cv::Point(6, size.height + 5), cv::FONT_HERSHEY_SIMPLEX, font_scale,
              cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
}

}  // namespace nadir::nodes
