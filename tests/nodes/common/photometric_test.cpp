// The VOs' vignetting correction: a frame divided by the lens's vignetting as
// its response saw it, I / V^(1 / gamma), V = 1 / (1 + k r^2)^2.

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include <opencv2/core.hpp>

#include "nodes/common/photometric.h"

namespace nadir::vo {
namespace {

// 640 x 480, f = 500 px, principal point at the centre (319.5, 239.5).
const cv::Matx33d kK(500, 0, 319.5, 0, 500, 239.5, 0, 0, 1);

// k for V = 0.5 at the corner: r_corner^2 = (319.5^2 + 239.5^2) / 500^2.
double kHalfAtCorner() {
  const double r2 = (319.5 * 319.5 + 239.5 * 239.5) / (500.0 * 500.0);
  return (1.0 / std::sqrt(0.5) - 1.0) / r2;
}

// Linear response, half the light at the corner: a flat 100-count frame
// comes back flat: 100 at the centre, 100 / 0.5 = 200 at the corner, and at
// (160, 120), r^2 = (159.5^2 + 119.5^2) / 500^2, 100 (1 + k r^2)^2.
TEST(VignettingCorrection, DividesAFlatFrameByTheVignetting) {
  const cv::Mat flat(480, 640, CV_8UC1, cv::Scalar(100));
  VignettingCorrection correction;
  const cv::Mat out = correction.apply(flat, kK, {.vignetting_corner = 0.5, .response_gamma = 1.0});
  EXPECT_EQ(out.at<std::uint8_t>(240, 320), 100);
  EXPECT_EQ(out.at<std::uint8_t>(0, 0), 200);
  EXPECT_EQ(out.at<std::uint8_t>(479, 639), 200);
  const double r2 = (159.5 * 159.5 + 119.5 * 119.5) / (500.0 * 500.0);
  EXPECT_NEAR(out.at<std::uint8_t>(120, 160), 100.0 * std::pow(1.0 + kHalfAtCorner() * r2, 2), 0.6);
}

// Through a gamma of 2.2 the corner read 100 (0.5)^(1 / 2.2): the correction
// multiplies by 2^(1 / 2.2) = 1.3703, to 137.
TEST(VignettingCorrection, DividesAsTheResponseSawTheVignetting) {
  const cv::Mat flat(480, 640, CV_8UC1, cv::Scalar(100));
  VignettingCorrection correction;
  const cv::Mat out = correction.apply(flat, kK, {.vignetting_corner = 0.5, .response_gamma = 2.2});
  EXPECT_EQ(out.at<std::uint8_t>(0, 0), 137);
  EXPECT_EQ(out.at<std::uint8_t>(240, 320), 100);
}

// What would be brighter than 255 saturates there, as the camera would have.
TEST(VignettingCorrection, SaturatesAt255) {
  const cv::Mat bright(480, 640, CV_8UC1, cv::Scalar(200));
  VignettingCorrection correction;
  const cv::Mat out = correction.apply(bright, kK, {.vignetting_corner = 0.5});
  EXPECT_EQ(out.at<std::uint8_t>(0, 0), 255);
  EXPECT_EQ(out.at<std::uint8_t>(240, 320), 200);
}

// A lens without vignetting leaves the frame as it is (the same pixels, not a copy);
// a colour frame is refused with a message saying why.
TEST(VignettingCorrection, LeavesAFlatLensAloneAndRefusesColour) {
  const cv::Mat flat(48, 64, CV_8UC1, cv::Scalar(100));
  VignettingCorrection correction;
  EXPECT_EQ(correction.apply(flat, kK, {}).data, flat.data);
  const cv::Mat colour(48, 64, CV_8UC3, cv::Scalar(100, 100, 100));
  EXPECT_THROW(correction.apply(colour, kK, {.vignetting_corner = 0.5}), std::invalid_argument);
}

}  // namespace
}  // namespace nadir::vo
