#pragma once

#include <opencv2/core/mat.hpp>

namespace nadir::render {

// A seamlessly tiling 512 x 512 gray pattern (CV_8UC1) of clumpy multi-scale
// noise, mean 128, used to add texture finer than the imagery. Deterministic.
cv::Mat makeDetailTexture();

}  // namespace nadir::render
