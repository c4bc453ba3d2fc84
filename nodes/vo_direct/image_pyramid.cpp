#include "nodes/vo_direct/image_pyramid.h"

#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace nadir::vo {

namespace {

// Gaussian 5-tap low-pass and every second pixel (cv::pyrDown): a 2x2 box
// average leaves enough of a sharp texture's fine detail to alias, and the
// coarse levels then disagree between frames.
cv::Mat halve(const cv::Mat& fine) {
  cv::Mat coarse;
  cv::pyrDown(fine, coarse, cv::Size(fine.cols / 2, fine.rows / 2));
  return coarse;
}

}  // namespace

ImagePyramid::ImagePyramid(const cv::Mat& gray, int levels, int first_gradient_level) {
  if (gray.empty() || gray.type() != CV_8UC1)
    throw std::invalid_argument("ImagePyramid: needs an 8-bit single-channel image");
  if (levels < 1) throw std::invalid_argument("ImagePyramid: needs at least one level");
  intensity_.resize(levels);
  samples_.resize(levels);
  gray.convertTo(intensity_[0], CV_32F);
  for (int l = 1; l < levels; ++l) {
    if (intensity_[l - 1].cols < 8 || intensity_[l - 1].rows < 8)
      throw std::invalid_argument("ImagePyramid: the image is too small for " +
                                  std::to_string(levels) + " levels");
    intensity_[l] = halve(intensity_[l - 1]);
  }
  for (int l = std::max(0, first_gradient_level); l < levels; ++l) computeGradients(l);
}

void ImagePyramid::computeGradients(int level) {
  if (hasGradients(level)) return;
  const cv::Mat& I = intensity_[level];
  cv::Mat& out = samples_[level];
  out.create(I.rows, I.cols, CV_32FC3);
  if (level == 0) I.convertTo(level0_bytes_, CV_8U);
  for (int y = 0; y < I.rows; ++y) {
    const float* row = I.ptr<float>(y);
    const float* up = I.ptr<float>(std::max(y - 1, 0));
    const float* down = I.ptr<float>(std::min(y + 1, I.rows - 1));
    const float dy_scale = (y == 0 || y == I.rows - 1) ? 1.f : 0.5f;
    float* o = out.ptr<float>(y);
    // The borders take one-sided differences; the interior runs without branches.
    const int last = I.cols - 1;
    for (int x = 1; x < last; ++x) {
      o[3 * x] = row[x];
      o[3 * x + 1] = 0.5f * (row[x + 1] - row[x - 1]);
      o[3 * x + 2] = (down[x] - up[x]) * dy_scale;
    }
    for (const int x : {0, last}) {
      const int xl = std::max(x - 1, 0);
      const int xr = std::min(x + 1, last);
      o[3 * x] = row[x];
      o[3 * x + 1] = row[xr] - row[xl];
      o[3 * x + 2] = (down[x] - up[x]) * dy_scale;
    }
  }
}

}  // namespace nadir::vo
