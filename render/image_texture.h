#pragma once
// How much texture an image holds, so that a user can say how hard a world is
// for vision: gradient statistics and corner counts of 8-bit gray images,
// summed over the frames of a run. docs/rendering.md says what each means.

#include <cstddef>
#include <string>

#include <opencv2/core/mat.hpp>

namespace nadir::render {

struct ImageTexture {
  std::size_t frames = 0;
  // Central-difference gradient magnitude, counts per pixel: the mean and the
  // median over every pixel of every frame (the median from a histogram of
  // 0.25-count bins).
  double mean_gradient = 0.0;
  double median_gradient = 0.0;
  // Share of the pixels whose gradient exceeds kTexturedGradient.
  double textured_share = 0.0;
  // FAST-9 corners (threshold kFastThreshold, non-maximum suppressed) per
  // frame and per megapixel.
  double corners_per_megapixel = 0.0;
};

inline constexpr double kTexturedGradient = 8.0;
inline constexpr int kFastThreshold = 20;

// Sums the texture of 8-bit frames (gray, or RGB taken as its mean).
class TextureMeter {
 public:
  // Throws std::invalid_argument for an empty or non-8-bit image.
  void add(const cv::Mat& image);
  ImageTexture result() const;

 private:
  static constexpr int kBins = 1024;  // 0.25 counts each, to 256
  std::size_t frames_ = 0;
  double pixels_ = 0.0;
  double gradient_sum_ = 0.0;
  double textured_ = 0.0;
  double corners_ = 0.0;
  double histogram_[kBins] = {};
};

// "texture: mean gradient 6.1 counts/px (median 3.2), 21.4 % of pixels above 8,
// 512 corners/Mpx, over 140 frames".
std::string formatTexture(const ImageTexture& texture);

}  // namespace nadir::render
