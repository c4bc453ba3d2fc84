#pragma once
// The status line of the VO nodes' debug images: white text on a black box at
// the top left, sized to the image.

#include <string>

#include <opencv2/core.hpp>

namespace nadir::nodes {

void drawStatusLine(cv::Mat& rgb, const std::string& text);

}  // namespace nadir::nodes
