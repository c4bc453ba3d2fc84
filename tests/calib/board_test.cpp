// The board: parsing its size, its object points, the corner order, and
// detection on OpenCV's sample photographs.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "calib/board.h"
#include "tests/calib/opencv_photos.h"

namespace nadir::calib {
namespace {

const BoardSpec kPhotoBoard{.inner_cols = 9, .inner_rows = 6, .square_m = 0.025};

// Expects std::invalid_argument whose message contains `needle`.
template <typename F>
void expectInvalid(F&& f, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "no exception; expected one mentioning '" << needle << "'";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

// "9x6" and "12X8" give those inner-corner counts and the square's side.
TEST(Board, ParsesColsByRows) {
  const BoardSpec b = parseBoardSpec("9x6", 0.025);
  EXPECT_EQ(b.inner_cols, 9);
  EXPECT_EQ(b.inner_rows, 6);
  EXPECT_DOUBLE_EQ(b.square_m, 0.025);
  const BoardSpec c = parseBoardSpec("12X8", 0.03);
  EXPECT_EQ(c.inner_cols, 12);
  EXPECT_EQ(c.inner_rows, 8);
  EXPECT_EQ(c.patternSize(), cv::Size(12, 8));
  EXPECT_EQ(c.cornerCount(), 96);
}

// Malformed sizes and non-positive squares are refused, each message naming
// the text and what is wrong with it.
TEST(Board, RefusesBadBoards) {
  expectInvalid([] { parseBoardSpec("9x", 0.025); }, "board '9x'");
  expectInvalid([] { parseBoardSpec("9x", 0.025); }, "after the x");
  expectInvalid([] { parseBoardSpec("0x6", 0.025); }, "inner_cols = 0");
  expectInvalid([] { parseBoardSpec("9x2", 0.025); }, "inner_rows = 2");
  expectInvalid([] { parseBoardSpec("x6", 0.025); }, "before the x");
  expectInvalid([] { parseBoardSpec("96", 0.025); }, "COLSxROWS");
  expectInvalid([] { parseBoardSpec("9x6x", 0.025); }, "after the x");
  expectInvalid([] { parseBoardSpec("-9x6", 0.025); }, "inner_cols = -9");
  expectInvalid([] { parseBoardSpec("9x6", 0.0); }, "square_m = 0");
  expectInvalid([] { parseBoardSpec("9x6", -0.025); }, "square_m = -0.025");
  expectInvalid([] { parseBoardSpec("9x6", std::numeric_limits<double>::quiet_NaN()); },
                "square_m");
}

// Corner (row r, col c) is at (c s, r s, 0), row-major.
TEST(Board, ObjectPointsAreRowMajor) {
  const std::vector<cv::Point3f> p = boardObjectPoints(kPhotoBoard);
  ASSERT_EQ(p.size(), 54u);
  EXPECT_EQ(p[0], cv::Point3f(0, 0, 0));
  EXPECT_NEAR(p[1].x, 0.025, 1e-7);  // along the row
  EXPECT_NEAR(p[9].y, 0.025, 1e-7);  // next row
  EXPECT_NEAR(p[9].x, 0.0, 1e-7);
  EXPECT_NEAR(p[53].x, 0.2, 1e-7);    // 8 squares
  EXPECT_NEAR(p[53].y, 0.125, 1e-7);  // 5 squares
  for (const cv::Point3f& q : p) EXPECT_EQ(q.z, 0.0f);
}

std::vector<cv::Point2f> frontalGrid(int cols, int rows, cv::Point2f origin, float step) {
  std::vector<cv::Point2f> g;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) g.emplace_back(origin.x + step * c, origin.y + step * r);
  return g;
}

// A grid returned reversed (the board turned half round) is put back with its
// first corner at the top-left; a square grid returned a quarter turn round
// likewise; a grid already canonical is left alone.
TEST(Board, CanonicalOrderStartsTopLeft) {
  const std::vector<cv::Point2f> grid = frontalGrid(9, 6, {100, 50}, 20);
  std::vector<cv::Point2f> reversed(grid.rbegin(), grid.rend());
  canonicalCornerOrder(reversed, kPhotoBoard);
  EXPECT_EQ(reversed, grid);
  std::vector<cv::Point2f> same = grid;
  canonicalCornerOrder(same, kPhotoBoard);
  EXPECT_EQ(same, grid);

  const BoardSpec square{.inner_cols = 4, .inner_rows = 4, .square_m = 0.02};
  const std::vector<cv::Point2f> g4 = frontalGrid(4, 4, {100, 50}, 20);
  // A quarter turn: output (r, c) takes input (c, 3 - r).
  std::vector<cv::Point2f> turned(16);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) turned[r * 4 + c] = g4[c * 4 + (3 - r)];
  canonicalCornerOrder(turned, square);
  EXPECT_EQ(turned, g4);
}

// All 13 photographs: the board is found, 54 corners inside the image, the
// first one the outer corner nearest the top-left (of it and the last), and
// the photographs count as sharp (under 4 px: OpenCV calls ~3 px sharp).
TEST(Board, FindsBoardInAllPhotographs) {
  for (const std::string& name : test::photoNames()) {
    const cv::Mat gray = test::loadPhoto(name);
    ASSERT_FALSE(gray.empty()) << name;
    const std::optional<Detection> d = detectBoard(gray, kPhotoBoard);
    ASSERT_TRUE(d.has_value()) << name;
    ASSERT_EQ(d->corners_px.size(), 54u) << name;
    for (const cv::Point2f& p : d->corners_px) {
      EXPECT_TRUE(p.x >= 0 && p.y >= 0 && p.x < 640 && p.y < 480) << name;
    }
    EXPECT_LE(cv::norm(d->corners_px.front()), cv::norm(d->corners_px.back())) << name;
    EXPECT_GT(d->sharpness_px, 1.0) << name;
    EXPECT_LT(d->sharpness_px, 4.0) << name;
    std::printf("%s: %s, sharpness %.2f px\n", name.c_str(), detectorName(d->detector),
                d->sharpness_px);
  }
}

// A BGR image gives the same corners as its grey version.
TEST(Board, ColourImageGivesTheSameCorners) {
  const cv::Mat gray = test::loadPhoto("left01");
  cv::Mat bgr;
  cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
  const std::optional<Detection> a = detectBoard(gray, kPhotoBoard);
  const std::optional<Detection> b = detectBoard(bgr, kPhotoBoard);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->corners_px, b->corners_px);
}

// No board in the image: nothing found. A wrong image is an error.
TEST(Board, NoBoardAndBadImages) {
  cv::Mat noise(480, 640, CV_8UC1);
  cv::RNG(3).fill(noise, cv::RNG::UNIFORM, 0, 256);
  EXPECT_FALSE(detectBoard(noise, kPhotoBoard).has_value());
  EXPECT_FALSE(detectBoard(cv::Mat(480, 640, CV_8UC1, cv::Scalar(128)), kPhotoBoard).has_value());
  expectInvalid([] { detectBoard(cv::Mat(), kPhotoBoard); }, "empty");
  expectInvalid([] { detectBoard(cv::Mat(480, 640, CV_16UC1, cv::Scalar(0)), kPhotoBoard); },
                "8-bit");
  expectInvalid(
      [] { detectBoard(cv::Mat(480, 640, CV_8UC1, cv::Scalar(0)), BoardSpec{.inner_cols = 2}); },
      "inner_cols = 2");
}

}  // namespace
}  // namespace nadir::calib
