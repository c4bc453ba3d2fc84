#pragma once
// An image pyramid for direct alignment: each level halves the one below
// (Gaussian low-pass, every second pixel: level-l pixel x sits on level-0
// pixel x * 2^l) and holds, per pixel, the intensity and its central-difference
// gradient (d/dx, d/dy) interleaved, so that one bilinear lookup gives all three.

#include <cstddef>
#include <vector>

#include <opencv2/core.hpp>

#include "nodes/vo_direct/camera_model.h"

namespace nadir::vo {

struct IntensitySample {
  float intensity;
  float dx;
  float dy;
};

class ImagePyramid {
 public:
  ImagePyramid() = default;
  // gray: 8-bit. levels >= 1; gradients are computed for levels from
  // first_gradient_level up (the finer ones hold intensity only until
  // computeGradients is called for them).
  ImagePyramid(const cv::Mat& gray, int levels, int first_gradient_level = 0);

  int levels() const { return static_cast<int>(intensity_.size()); }
  int width(int level) const { return intensity_[level].cols; }
  int height(int level) const { return intensity_[level].rows; }
  // CV_32F.
  const cv::Mat& intensity(int level) const { return intensity_[level]; }
  // CV_32FC3: intensity, d/dx, d/dy; empty where not computed.
  const cv::Mat& samples(int level) const { return samples_[level]; }
  bool hasGradients(int level) const { return !samples_[level].empty(); }
  // Level 0 also keeps its 8-bit intensities once its gradients are computed:
  // a key-frame's 1.2 MB instead of 14.7 MB, so that the window's lookups in
  // its key-frames stay in the cache.
  void computeGradients(int level);
  const cv::Mat& level0Bytes() const { return level0_bytes_; }

  // Bilinear lookup at (x, y) in the level's pixels; the caller keeps
  // 0 <= x < width - 1 and 0 <= y < height - 1.
  static IntensitySample sample(const cv::Mat& samples, float x, float y) {
    const int ix = static_cast<int>(x);
    const int iy = static_cast<int>(y);
    const float fx = x - static_cast<float>(ix);
    const float fy = y - static_cast<float>(iy);
    const float* row0 = samples.ptr<float>(iy) + 3 * ix;
    const float* row1 = row0 + samples.step1();
    const float w00 = (1.f - fx) * (1.f - fy), w01 = fx * (1.f - fy);
    const float w10 = (1.f - fx) * fy, w11 = fx * fy;
    return {w00 * row0[0] + w01 * row0[3] + w10 * row1[0] + w11 * row1[3],
            w00 * row0[1] + w01 * row0[4] + w10 * row1[1] + w11 * row1[4],
            w00 * row0[2] + w01 * row0[5] + w10 * row1[2] + w11 * row1[5]};
  }
  // The same lookup at level 0 from the 8-bit intensities, the gradients
  // worked out as computeGradients does (bit for bit the same result);
  // samples is used within a pixel of the border.
  static IntensitySample sampleLevel0(const cv::Mat& bytes, const cv::Mat& samples, float x,
                                      float y) {
    const int ix = static_cast<int>(x);
    const int iy = static_cast<int>(y);
    if (ix < 1 || iy < 1 || ix > bytes.cols - 3 || iy > bytes.rows - 3)
      return sample(samples, x, y);
    const float fx = x - static_cast<float>(ix);
    const float fy = y - static_cast<float>(iy);
    const std::size_t step = bytes.step[0];
    const unsigned char* r0 = bytes.data + static_cast<std::size_t>(iy) * step + ix;
    const unsigned char* rm = r0 - step;
    const unsigned char* r1 = r0 + step;
    const unsigned char* r2 = r1 + step;
    const auto f = [](unsigned char c) { return static_cast<float>(c); };
    const float w00 = (1.f - fx) * (1.f - fy), w01 = fx * (1.f - fy);
    const float w10 = (1.f - fx) * fy, w11 = fx * fy;
    return {w00 * f(r0[0]) + w01 * f(r0[1]) + w10 * f(r1[0]) + w11 * f(r1[1]),
            w00 * (0.5f * (f(r0[1]) - f(r0[-1]))) + w01 * (0.5f * (f(r0[2]) - f(r0[0]))) +
                w10 * (0.5f * (f(r1[1]) - f(r1[-1]))) + w11 * (0.5f * (f(r1[2]) - f(r1[0]))),
            w00 * ((f(r1[0]) - f(rm[0])) * 0.5f) + w01 * ((f(r1[1]) - f(rm[1])) * 0.5f) +
                w10 * ((f(r2[0]) - f(r0[0])) * 0.5f) + w11 * ((f(r2[1]) - f(r0[1])) * 0.5f)};
  }
  static float sampleIntensity(const cv::Mat& intensity, float x, float y) {
    const int ix = static_cast<int>(x);
    const int iy = static_cast<int>(y);
    const float fx = x - static_cast<float>(ix);
    const float fy = y - static_cast<float>(iy);
    const float* row0 = intensity.ptr<float>(iy) + ix;
    const float* row1 = row0 + intensity.step1();
    return (1.f - fy) * ((1.f - fx) * row0[0] + fx * row0[1]) +
           fy * ((1.f - fx) * row1[0] + fx * row1[1]);
  }

 private:
  std::vector<cv::Mat> intensity_;
  std::vector<cv::Mat> samples_;
  cv::Mat level0_bytes_;
};

}  // namespace nadir::vo
