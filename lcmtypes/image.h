#pragma once
// image_t as a plain struct: a camera frame's pixels (lcmtypes/codec.h has its codec).

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace nadir::msg {

struct Image {
  std::int64_t utime = 0;
  // CV_8UC1 (gray) or CV_8UC3 with R first. Decoding gives these for GRAY, RGB,
  // BGR (converted) and MJPEG.
  cv::Mat pixels;
  // How encode() sends the pixels: 0 raw, 1-100 JPEG (MJPEG) of that quality.
  // decode() leaves it 0.
  int jpeg_quality = 0;
  // image_t's key-value metadata (exposure_s, ...), as sent.
  std::vector<std::pair<std::string, std::vector<std::uint8_t>>> metadata;

  // A metadata value as text; empty if there is no such key.
  std::string metadataText(const std::string& key) const;
};

}  // namespace nadir::msg
