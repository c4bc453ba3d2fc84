// View diversity against worked-out examples: ROS camera_calibration's X, Y,
// size and skew of boards placed by hand, its progress bars, and the
// auto-capture refusals.

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "calib/board.h"
#include "calib/coverage.h"
#include "tests/calib/opencv_photos.h"

namespace nadir::calib {
namespace {

const BoardSpec kBoard{.inner_cols = 9, .inner_rows = 6, .square_m = 0.025};
const cv::Size kImage(640, 480);

// A 9 x 6 grid whose outer corners are the parallelogram up_left, up_left +
// along (the last of the first row), up_left + down (the first of the last row).
std::vector<cv::Point2f> grid(cv::Point2d up_left, cv::Point2d along, cv::Point2d down) {
  std::vector<cv::Point2f> g;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 9; ++c) {
      const cv::Point2d p = up_left + along * (c / 8.0) + down * (r / 5.0);
      g.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y));
    }
  return g;
}

Detection detection(const std::vector<cv::Point2f>& corners, double sharpness_px = 2.0) {
  Detection d;
  d.corners_px = corners;
  d.sharpness_px = sharpness_px;
  return d;
}

// A frontal board centred in the image, 320 x 200 px: X = Y = 0.5 (the centre
// (320, 240) minus half the border sqrt(64000) over the image minus the
// border is exactly half), size = sqrt(64000 / 307200) = 0.456435, skew 0.
TEST(Coverage, FrontalCentredBoard) {
  const ViewParams p = viewParams(grid({160, 140}, {320, 0}, {0, 200}), kBoard, kImage);
  EXPECT_NEAR(p.x, 0.5, 1e-6);
  EXPECT_NEAR(p.y, 0.5, 1e-6);
  EXPECT_NEAR(p.size, 0.456435, 1e-6);
  EXPECT_NEAR(p.skew, 0.0, 1e-6);
}

// Outer corners on the image's corners: size = 1, X = Y = 0.5, skew 0.
TEST(Coverage, BoardFillingTheImage) {
  const ViewParams p = viewParams(grid({0, 0}, {640, 0}, {0, 480}), kBoard, kImage);
  EXPECT_NEAR(p.size, 1.0, 1e-6);
  EXPECT_NEAR(p.x, 0.5, 1e-5);
  EXPECT_NEAR(p.y, 0.5, 1e-5);
  EXPECT_NEAR(p.skew, 0.0, 1e-6);
}

// A sheared board, outer corners (100,100) (300,100) (350,300) (150,300): the
// angle at the top-right corner is 90 + atan(50/200) deg, so skew =
// 2 atan(0.25) = 0.489957; area 200 x 200, size = sqrt(40000 / 307200) =
// 0.360844; centre (225, 200), border 200: X = 125 / 440, Y = 100 / 280.
TEST(Coverage, ShearedBoard) {
  const ViewParams p = viewParams(grid({100, 100}, {200, 0}, {50, 200}), kBoard, kImage);
  EXPECT_NEAR(p.skew, 0.489957, 1e-5);
  EXPECT_NEAR(p.size, 0.360844, 1e-5);
  EXPECT_NEAR(p.x, 125.0 / 440.0, 1e-5);
  EXPECT_NEAR(p.y, 100.0 / 280.0, 1e-5);
  const ViewParams frontal = viewParams(grid({160, 140}, {320, 0}, {0, 200}), kBoard, kImage);
  // |0.284091 - 0.5| + |0.357143 - 0.5| + |0.360844 - 0.456435| + 0.489957
  EXPECT_NEAR(paramDistance(p, frontal), 0.215909 + 0.142857 + 0.095591 + 0.489957, 1e-5);
}

// ROS's progress bars: span over range, capped at 1, size and skew counted
// from 0; full when all four are full, or with 40 views whatever the spans.
TEST(Coverage, ProgressAndGoodEnough) {
  std::vector<ViewParams> kept = {{.x = 0.1, .y = 0.2, .size = 0.2, .skew = 0.1},
                                  {.x = 0.9, .y = 0.6, .size = 0.3, .skew = 0.3}};
  Coverage c = coverage(kept);
  EXPECT_NEAR(c.params[0].progress, 1.0, 1e-12);        // 0.8 / 0.7, capped
  EXPECT_NEAR(c.params[1].progress, 0.4 / 0.7, 1e-12);  // Y
  EXPECT_NEAR(c.params[2].progress, 0.3 / 0.4, 1e-12);  // size from 0
  EXPECT_NEAR(c.params[3].progress, 0.3 / 0.5, 1e-12);  // skew from 0
  EXPECT_EQ(c.params[2].min, 0.0);
  EXPECT_FALSE(c.good_enough);
  EXPECT_FALSE(goodEnough(kept));
  kept.push_back({.x = 0.5, .y = 0.95, .size = 0.45, .skew = 0.6});
  EXPECT_TRUE(goodEnough(kept));
  const std::vector<ViewParams> forty(40, ViewParams{.x = 0.5, .y = 0.5, .size = 0.3, .skew = 0});
  EXPECT_TRUE(goodEnough(forty));
  EXPECT_FALSE(goodEnough(std::vector<ViewParams>(39, forty[0])));
  EXPECT_FALSE(goodEnough({}));
}

// Auto-capture: the first view is kept; the same board moved 8 px is refused
// as a duplicate of view 0 (X moves by 8 / 387 = 0.02, under 0.2); moved
// 120 px (X by 0.31) it is kept.
TEST(Coverage, DuplicateRefused) {
  const std::vector<cv::Point2f> frontal = grid({160, 140}, {320, 0}, {0, 200});
  const ViewVerdict first = isGoodView(detection(frontal), kBoard, kImage, {});
  EXPECT_TRUE(first.keep());
  const std::vector<ViewParams> kept = {first.params};
  const ViewVerdict near =
      isGoodView(detection(grid({168, 140}, {320, 0}, {0, 200})), kBoard, kImage, kept);
  EXPECT_EQ(near.refusal, ViewRefusal::kDuplicate);
  EXPECT_EQ(near.nearest_view, 0);
  EXPECT_NEAR(near.nearest_distance, 8.0 / (640.0 - std::sqrt(64000.0)), 1e-5);
  EXPECT_NE(near.reason.find("duplicate"), std::string::npos) << near.reason;
  EXPECT_NE(near.reason.find("view 0"), std::string::npos) << near.reason;
  const ViewVerdict far =
      isGoodView(detection(grid({280, 140}, {320, 0}, {0, 200})), kBoard, kImage, kept);
  EXPECT_TRUE(far.keep()) << far.reason;
  EXPECT_NEAR(far.nearest_distance, 120.0 / (640.0 - std::sqrt(64000.0)), 1e-5);
}

// A photograph blurred with a sigma 3 px Gaussian is still detected but
// refused as blurred; the sharp original is kept.
TEST(Coverage, BlurredPhotographRefused) {
  const cv::Mat sharp = test::loadPhoto("left01");
  cv::Mat blurred;
  cv::GaussianBlur(sharp, blurred, cv::Size(), 3.0);
  const std::optional<Detection> d_sharp = detectBoard(sharp, kBoard);
  const std::optional<Detection> d_blurred = detectBoard(blurred, kBoard);
  ASSERT_TRUE(d_sharp && d_blurred);
  std::printf("sharpness: sharp %.2f px, blurred %.2f px\n", d_sharp->sharpness_px,
              d_blurred->sharpness_px);
  EXPECT_TRUE(isGoodView(d_sharp, kBoard, kImage, {}).keep());
  const ViewVerdict v = isGoodView(d_blurred, kBoard, kImage, {});
  EXPECT_EQ(v.refusal, ViewRefusal::kBlurred);
  EXPECT_NE(v.reason.find("blurred"), std::string::npos) << v.reason;
}

// A photograph with the board painted over: no detection, refused as no board.
TEST(Coverage, ImageWithoutBoardRefused) {
  cv::Mat photo = test::loadPhoto("left01");
  const std::optional<Detection> d = detectBoard(photo, kBoard);
  ASSERT_TRUE(d.has_value());
  // The board and a margin of about two squares around it.
  const cv::Rect box = cv::boundingRect(d->corners_px);
  const int margin = 2 * box.width / 8;
  cv::rectangle(
      photo,
      cv::Rect(box.x - margin, box.y - margin, box.width + 2 * margin, box.height + 2 * margin),
      cv::Scalar(128), cv::FILLED);
  const std::optional<Detection> none = detectBoard(photo, kBoard);
  EXPECT_FALSE(none.has_value());
  const ViewVerdict v = isGoodView(none, kBoard, kImage, {});
  EXPECT_EQ(v.refusal, ViewRefusal::kNoBoard);
  EXPECT_NE(v.reason.find("no board"), std::string::npos) << v.reason;
}

// Wrong corner counts and image sizes are errors that say so.
TEST(Coverage, BadInput) {
  std::vector<cv::Point2f> corners = grid({160, 140}, {320, 0}, {0, 200});
  corners.pop_back();
  EXPECT_THROW(viewParams(corners, kBoard, kImage), std::invalid_argument);
  EXPECT_THROW(viewParams(grid({160, 140}, {320, 0}, {0, 200}), kBoard, cv::Size(0, 480)),
               std::invalid_argument);
}

}  // namespace
}  // namespace nadir::calib
