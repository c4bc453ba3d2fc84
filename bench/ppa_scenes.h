#pragma once
// Synthetic scenes for the on-sensor programs' benchmark and tests: a textured
// ground to align, cluttered scenes, and terrain's target mats pasted in.

#include <cmath>
#include <cstdint>
#include <random>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "nodes/ppa/ppa_array.h"
#include "terrain/targets.h"

namespace nadir::ppa::test {

inline constexpr double kCentrePx = (kWidth - 1) / 2.0;

// A gray texture of random rectangles and ellipses of random brightness on
// gray (sharp-edged patches, like fields and roofs from above), lightly blurred.
inline cv::Mat patchTexture(int size, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  cv::Mat texture(size, size, CV_8UC1, cv::Scalar(128));
  const int shapes = size * size / 300;
  for (int i = 0; i < shapes; ++i) {
    const cv::Point centre(static_cast<int>(u(rng) * size), static_cast<int>(u(rng) * size));
    const int a = 3 + static_cast<int>(u(rng) * 18), b = 3 + static_cast<int>(u(rng) * 18);
    const cv::Scalar gray(20 + static_cast<int>(u(rng) * 215));
    if (u(rng) < 0.5) {
      cv::rectangle(texture, cv::Rect(centre.x - a, centre.y - b, 2 * a, 2 * b), gray, cv::FILLED);
    } else {
      cv::ellipse(texture, centre, cv::Size(a, b), u(rng) * 180.0, 0.0, 360.0, gray, cv::FILLED,
                  cv::LINE_AA);
    }
  }
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 0.7);
  return texture;
}

// The 256x256 frame of a camera over `texture` whose pixel p shows the
// texture at origin + c + t + scale R(theta) (p - c), c the frame's centre,
// R(theta) clockwise in the image: what VisualOdometryResult reports (t,
// theta, scale) for this frame against the frame at t = 0, theta = 0, scale = 1.
inline cv::Mat viewOf(const cv::Mat& texture, double origin_x, double origin_y, double tx,
                      double ty, double theta, double scale) {
  const double c = std::cos(theta) * scale, s = std::sin(theta) * scale;
  cv::Mat map = (cv::Mat_<double>(2, 3) << c, -s, origin_x + kCentrePx + tx - (c - s) * kCentrePx,
                 s, c, origin_y + kCentrePx + ty - (s + c) * kCentrePx);
  cv::Mat frame;
  cv::warpAffine(texture, frame, map, cv::Size(kWidth, kHeight),
                 cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REFLECT);
  return frame;
}

// Sets the frame as the light on the array.
inline void expose(Ppa& ppa, const cv::Mat& frame) {
  CV_Assert(frame.type() == CV_8UC1 && frame.cols == kWidth && frame.rows == kHeight);
  const cv::Mat contiguous = frame.isContinuous() ? frame : frame.clone();
  ppa.setLight(contiguous.ptr<std::uint8_t>());
}

// A cluttered 256x256 scene on a bright, mottled ground: random blobs of any
// brightness, dark and bright lines and fine texture.
inline cv::Mat clutterScene(std::uint32_t seed, int blobs = 40, int lines = 25) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  cv::RNG cv_rng(seed);
  cv::Mat noise(kHeight / 8, kWidth / 8, CV_8UC1);
  cv_rng.fill(noise, cv::RNG::UNIFORM, 170, 230);
  cv::Mat scene;
  cv::resize(noise, scene, cv::Size(kWidth, kHeight), 0, 0, cv::INTER_CUBIC);
  const auto point = [&] {
    return cv::Point(static_cast<int>(u(rng) * kWidth), static_cast<int>(u(rng) * kHeight));
  };
  for (int i = 0; i < blobs; ++i) {
    const cv::Size axes(2 + static_cast<int>(u(rng) * 16), 2 + static_cast<int>(u(rng) * 16));
    cv::ellipse(scene, point(), axes, u(rng) * 180.0, 0.0, 360.0,
                cv::Scalar(static_cast<int>(u(rng) * 255)), cv::FILLED, cv::LINE_AA);
  }
  for (int i = 0; i < lines; ++i) {
    cv::line(scene, point(), point(), cv::Scalar(static_cast<int>(u(rng) * 255)),
             1 + static_cast<int>(u(rng) * 3), cv::LINE_AA);
  }
  cv::Mat grain(kHeight, kWidth, CV_16S);
  cv_rng.fill(grain, cv::RNG::NORMAL, 0, 6);
  cv::Mat scene16;
  scene.convertTo(scene16, CV_16S);
  scene16 += grain;
  scene16.convertTo(scene, CV_8U);
  return scene;
}

// terrain's mat (target.kind, rings) as size_px square gray pixels.
inline cv::Mat matImage(const terrain::GroundTarget& target, int size_px) {
  cv::Mat gray;
  cv::cvtColor(terrain::targetTexture(target, size_px), gray, cv::COLOR_RGB2GRAY);
  return gray;
}

// Pastes `mat` into `scene` with its top-left pixel at (x0, y0).
inline void paste(cv::Mat& scene, const cv::Mat& mat, int x0, int y0) {
  mat.copyTo(scene(cv::Rect(x0, y0, mat.cols, mat.rows)));
}

}  // namespace nadir::ppa::test
