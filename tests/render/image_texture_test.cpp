// The texture measure against images whose statistics are worked out by hand.

#include "render/image_texture.h"

#include <gtest/gtest.h>

#include <cmath>

#include <opencv2/imgproc.hpp>

namespace nadir::render {
namespace {

// I = 2x + y: every interior gradient is (2, 1), |g| = sqrt(5) = 2.236; the
// median's 0.25-count bin is [2.0, 2.25), reported at its middle, 2.125; no
// pixel above 8, no corner.
TEST(TextureMeter, ARampHasItsSlope) {
  cv::Mat ramp(60, 80, CV_8U);
  for (int y = 0; y < ramp.rows; ++y)
    for (int x = 0; x < ramp.cols; ++x) ramp.at<std::uint8_t>(y, x) = 2 * x + y;
  TextureMeter meter;
  meter.add(ramp);
  const ImageTexture t = meter.result();
  EXPECT_EQ(t.frames, 1u);
  EXPECT_NEAR(t.mean_gradient, std::sqrt(5.0), 1e-9);
  EXPECT_DOUBLE_EQ(t.median_gradient, 2.125);
  EXPECT_EQ(t.textured_share, 0.0);
  EXPECT_EQ(t.corners_per_megapixel, 0.0);
}

cv::Mat squares() {
  cv::Mat image(120, 160, CV_8U, cv::Scalar(20));
  for (int i = 0; i < 6; ++i) {
    const int x0 = 14 + (i % 3) * 50, y0 = 20 + (i / 3) * 50;
    image(cv::Rect(x0, y0, 16, 16)).setTo(200);
  }
  return image;
}

// Six 16 px squares of 200 on 20 in 160x120. Per square, 120 edge pixels have
// a central difference of 90 and its 4 inner corner pixels (90, 90): 124
// textured pixels and a gradient sum of 120 x 90 + 4 x 127.28 = 11309.1, over
// the 158 x 118 interior pixels: 3.99 % and 3.640 counts/px.
TEST(TextureMeter, SquaresOnAPlainGround) {
  TextureMeter meter;
  meter.add(squares());
  meter.add(squares());
  const ImageTexture t = meter.result();
  EXPECT_EQ(t.frames, 2u);
  EXPECT_NEAR(t.textured_share, 6.0 * 124.0 / (158.0 * 118.0), 1e-12);
  EXPECT_NEAR(t.mean_gradient,
              6.0 * (120.0 * 90.0 + 4.0 * std::hypot(90.0, 90.0)) / (158.0 * 118.0), 1e-9);
}

// Softened as a lens would (FAST cannot rank the ties of a perfect step), each
// square gives its 4 corners: 24 in 19200 px, 1250 per megapixel.
TEST(TextureMeter, CountsTheCornersOfTheSquares) {
  cv::Mat image = squares();
  cv::GaussianBlur(image, image, cv::Size(5, 5), 1.0);
  TextureMeter meter;
  meter.add(image);
  EXPECT_NEAR(meter.result().corners_per_megapixel, 24.0 * 1e6 / 19200.0, 1e-6);
}

TEST(TextureMeter, RefusesWhatIsNotAnEightBitImage) {
  TextureMeter meter;
  EXPECT_THROW(meter.add(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(meter.add(cv::Mat(4, 4, CV_32F, cv::Scalar(0))), std::invalid_argument);
  EXPECT_EQ(meter.result().frames, 0u);
}

}  // namespace
}  // namespace nadir::render
