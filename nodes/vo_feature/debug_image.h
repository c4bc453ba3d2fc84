#pragma once
// The feature VO's debug image (the thesis's figure 21, ORB-SLAM2's frame
// view): the camera frame with the features matched to the map drawn as green
// boxes, the others as small dots, and a status line.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace nadir::vo {

struct DebugFeature {
  cv::Point2f px;
  int octave = 0;
  bool tracked = false;  // matched to a map point in this frame
};

// An RGB (R first) copy of an 8-bit grey or RGB frame with the features and
// the status text drawn on it. Throws std::invalid_argument for other images.
cv::Mat drawDebugImage(const cv::Mat& frame, const std::vector<DebugFeature>& features,
                       const std::string& status_text);

}  // namespace nadir::vo
