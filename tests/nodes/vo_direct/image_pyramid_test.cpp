// The image pyramid's lookups: the level-0 lookup from 8-bit intensities must
// give what the float lookup gives, bit for bit, everywhere in the image.

#include "nodes/vo_direct/image_pyramid.h"

#include <gtest/gtest.h>

#include <random>

namespace nadir::vo {
namespace {

TEST(ImagePyramid, GradientsAreCentralDifferencesWorkedOutByHand) {
  // A ramp of 3 counts a column and 5 a row: d/dx = 3, d/dy = 5 inside.
  cv::Mat gray(16, 20, CV_8U);
  for (int y = 0; y < gray.rows; ++y)
    for (int x = 0; x < gray.cols; ++x) gray.at<unsigned char>(y, x) = 3 * x + 5 * y;
  const ImagePyramid pyramid(gray, 1, 0);
  const IntensitySample s = ImagePyramid::sample(pyramid.samples(0), 4.25f, 7.5f);
  EXPECT_FLOAT_EQ(s.intensity, 3 * 4.25f + 5 * 7.5f);
  EXPECT_FLOAT_EQ(s.dx, 3.f);
  EXPECT_FLOAT_EQ(s.dy, 5.f);
  const IntensitySample b =
      ImagePyramid::sampleLevel0(pyramid.level0Bytes(), pyramid.samples(0), 4.25f, 7.5f);
  EXPECT_FLOAT_EQ(b.intensity, 3 * 4.25f + 5 * 7.5f);
  EXPECT_FLOAT_EQ(b.dx, 3.f);
  EXPECT_FLOAT_EQ(b.dy, 5.f);
}

TEST(ImagePyramid, ByteLookupAtLevelZeroEqualsTheFloatLookupBitForBit) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> count(0, 255);
  cv::Mat gray(48, 64, CV_8U);
  for (int y = 0; y < gray.rows; ++y)
    for (int x = 0; x < gray.cols; ++x) gray.at<unsigned char>(y, x) = count(rng);
  ImagePyramid pyramid(gray, 3, 1);
  EXPECT_TRUE(pyramid.level0Bytes().empty());  // only once level 0 has gradients
  pyramid.computeGradients(0);
  ASSERT_EQ(pyramid.level0Bytes().size(), gray.size());
  // Everywhere the lookup is allowed, the borders included.
  std::uniform_real_distribution<float> x(0.f, gray.cols - 1.001f), y(0.f, gray.rows - 1.001f);
  for (int i = 0; i < 20000; ++i) {
    const float u = i < 200 ? static_cast<float>(i % 63) : x(rng);
    const float v = i < 200 ? static_cast<float>(i / 63) * 15.f : y(rng);
    const IntensitySample a = ImagePyramid::sample(pyramid.samples(0), u, v);
    const IntensitySample b =
        ImagePyramid::sampleLevel0(pyramid.level0Bytes(), pyramid.samples(0), u, v);
    ASSERT_EQ(a.intensity, b.intensity) << u << ", " << v;
    ASSERT_EQ(a.dx, b.dx) << u << ", " << v;
    ASSERT_EQ(a.dy, b.dy) << u << ", " << v;
  }
}

}  // namespace
}  // namespace nadir::vo
