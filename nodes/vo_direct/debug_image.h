#pragma once
// The direct VO's debug image (the thesis's figure 20, DSO's key-frame view):
// the newest key-frame with the window's points drawn over it, coloured by
// inverse depth (near red, far blue), and a status line.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "nodes/vo_direct/frame_tracker.h"

namespace nadir::vo {

// An RGB (R first) image; throws std::invalid_argument unless keyframe is 8-bit gray.
cv::Mat drawDirectDebugImage(const cv::Mat& keyframe, const std::vector<DepthPixel>& points,
                             const std::string& status_text);

}  // namespace nadir::vo
