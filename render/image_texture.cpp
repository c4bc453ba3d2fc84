#include "render/image_texture.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

namespace nadir::render {

void TextureMeter::add(const cv::Mat& image) {
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3))
    throw std::invalid_argument("TextureMeter: needs an 8-bit gray or RGB image");
  cv::Mat gray = image;
  if (image.channels() == 3) cv::cvtColor(image, gray, cv::COLOR_RGB2GRAY);
  for (int y = 1; y + 1 < gray.rows; ++y) {
    const std::uint8_t* up = gray.ptr<std::uint8_t>(y - 1);
    const std::uint8_t* row = gray.ptr<std::uint8_t>(y);
    const std::uint8_t* down = gray.ptr<std::uint8_t>(y + 1);
    for (int x = 1; x + 1 < gray.cols; ++x) {
      const double gx = 0.5 * (row[x + 1] - row[x - 1]);
      const double gy = 0.5 * (down[x] - up[x]);
      const double g = std::sqrt(gx * gx + gy * gy);
      gradient_sum_ += g;
      textured_ += g > kTexturedGradient ? 1.0 : 0.0;
      ++histogram_[std::min(kBins - 1, static_cast<int>(g * 4.0))];
      pixels_ += 1.0;
    }
  }
  std::vector<cv::KeyPoint> corners;
  cv::FAST(gray, corners, kFastThreshold, true);
  corners_ += static_cast<double>(corners.size()) * 1e6 / static_cast<double>(gray.total());
  ++frames_;
}

ImageTexture TextureMeter::result() const {
  ImageTexture out;
  out.frames = frames_;
  if (frames_ == 0 || pixels_ == 0.0) return out;
  out.mean_gradient = gradient_sum_ / pixels_;
  out.textured_share = textured_ / pixels_;
  out.corners_per_megapixel = corners_ / static_cast<double>(frames_);
  double seen = 0.0;
  for (int b = 0; b < kBins; ++b) {
    seen += histogram_[b];
    if (seen >= 0.5 * pixels_) {
      out.median_gradient = (b + 0.5) / 4.0;
      break;
    }
  }
  return out;
}

std::string formatTexture(const ImageTexture& texture) {
  char line[256];
  std::snprintf(line, sizeof line,
                "texture: mean gradient %.1f counts/px (median %.1f), %.1f %% of pixels above "
                "%.0f, %.0f corners/Mpx, over %zu frames",
                texture.mean_gradient, texture.median_gradient, 100.0 * texture.textured_share,
                kTexturedGradient, texture.corners_per_megapixel, texture.frames);
  return line;
}

}  // namespace nadir::render
