// On-sensor target extraction on cluttered synthetic scenes with terrain's
// concentric mat pasted in at known places.

#include "nodes/ppa/target_extraction.h"

#include <gtest/gtest.h>

#include <cmath>

#include "bench/ppa_scenes.h"

namespace nadir::ppa {
namespace {

constexpr int kMatPx = 66;  // 5 rings: 11 bands of 3 px from the edge to the centre
constexpr int kBandPx = 3;

TargetExtractionResult extract(const cv::Mat& scene,
                               const TargetExtractionParams& params = TargetExtractionParams{}) {
  Ppa ppa;
  test::expose(ppa, scene);
  return TargetExtractor(params).processFrame(ppa);
}

cv::Mat concentricMat() {
  terrain::GroundTarget target;
  target.kind = "concentric";
  target.rings = 5;
  return test::matImage(target, kMatPx);
}

// Expects the box `in` bands in from the edges of the mat pasted at (x0, y0), within 2 px.
void expectBox(const TargetExtractionResult& result, int x0, int y0, int in) {
  ASSERT_TRUE(result.detected);
  EXPECT_NEAR(result.box.x_min, x0 + in * kBandPx, 2);
  EXPECT_NEAR(result.box.y_min, y0 + in * kBandPx, 2);
  EXPECT_NEAR(result.box.x_max, x0 + kMatPx - 1 - in * kBandPx, 2);
  EXPECT_NEAR(result.box.y_max, y0 + kMatPx - 1 - in * kBandPx, 2);
  EXPECT_NEAR(result.center_x_px, x0 + (kMatPx - 1) / 2.0, 1.0);
  EXPECT_NEAR(result.center_y_px, y0 + (kMatPx - 1) / 2.0, 1.0);
}

// In cluttered scenes (several seeds) the mat is found: after 6 rounds on its
// bright surround, bands 7, 9 are left, so the box is 7 bands in from the mat's edge.
TEST(TargetExtractionTest, FindsTheMatInClutter) {
  const cv::Mat mat = concentricMat();
  for (std::uint32_t seed = 1; seed <= 6; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    cv::Mat scene = test::clutterScene(seed);
    const int x0 = 10 + static_cast<int>((seed * 37) % 170);
    const int y0 = 10 + static_cast<int>((seed * 53) % 170);
    test::paste(scene, mat, x0, y0);
    const TargetExtractionResult result = extract(scene);
    expectBox(result, x0, y0, 7);
    EXPECT_GT(result.instructions, 0u);
  }
}

// Fewer rounds leave more of the mat: after 4, bands 5, 7, 9 (5 bands in).
TEST(TargetExtractionTest, FewerBoundariesLeaveMoreOfTheMat) {
  cv::Mat scene = test::clutterScene(3);
  test::paste(scene, concentricMat(), 100, 70);
  TargetExtractionParams params;
  params.boundaries = 4;
  expectBox(extract(scene, params), 100, 70, 5);
}

// On a dark surround the mat's margin is one boundary more and what is left
// is dark bands again: bands 5, 7, 9, two bands wider; the centre is the same.
TEST(TargetExtractionTest, DarkSurroundLeavesTwoBandsMore) {
  cv::Mat scene(kHeight, kWidth, CV_8UC1, cv::Scalar(40));
  test::paste(scene, concentricMat(), 60, 120);
  expectBox(extract(scene), 60, 120, 5);
}

// The same scenes without the mat (and more seeds) give no target.
TEST(TargetExtractionTest, NothingInClutterWithoutTheMat) {
  for (std::uint32_t seed = 1; seed <= 12; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const TargetExtractionResult result = extract(test::clutterScene(seed, 60, 40));
    EXPECT_FALSE(result.detected);
  }
}

// A mat turned by 30 deg is found at its centre.
TEST(TargetExtractionTest, FindsATurnedMat) {
  const cv::Mat mat = concentricMat();
  const int canvas = 96;
  const double shift = (canvas - kMatPx) / 2.0;
  cv::Mat turn =
      cv::getRotationMatrix2D(cv::Point2f((canvas - 1) / 2.0f, (canvas - 1) / 2.0f), 30.0, 1.0);
  cv::Mat place = (cv::Mat_<double>(3, 3) << 1, 0, shift, 0, 1, shift, 0, 0, 1);
  cv::Mat affine = turn * place;
  cv::Mat turned, mask;
  cv::warpAffine(mat, turned, affine, cv::Size(canvas, canvas), cv::INTER_LINEAR);
  cv::warpAffine(cv::Mat(kMatPx, kMatPx, CV_8UC1, cv::Scalar(255)), mask, affine,
                 cv::Size(canvas, canvas), cv::INTER_NEAREST);
  cv::Mat scene = test::clutterScene(5);
  turned.copyTo(scene(cv::Rect(80, 90, canvas, canvas)), mask);
  const TargetExtractionResult result = extract(scene);
  ASSERT_TRUE(result.detected);
  EXPECT_NEAR(result.center_x_px, 80 + (canvas - 1) / 2.0, 1.5);
  EXPECT_NEAR(result.center_y_px, 90 + (canvas - 1) / 2.0, 1.5);
}

// Boxes outside the size limits are no target.
TEST(TargetExtractionTest, SizeLimitsDiscardBoxes) {
  cv::Mat scene = test::clutterScene(2);
  test::paste(scene, concentricMat(), 40, 40);
  TargetExtractionParams params;
  params.max_size_px = 20;  // the box is 24 px
  const TargetExtractionResult result = extract(scene, params);
  EXPECT_TRUE(result.box.found);
  EXPECT_FALSE(result.detected);
}

}  // namespace
}  // namespace nadir::ppa
