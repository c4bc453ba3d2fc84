#pragma once
// The checkerboard: its size, its corners in the board's own frame, and
// finding it in an image.
//
// Detection runs cv::findChessboardCornersSB (normalised image; exhaustive
// search only as a second try: on OpenCV's 13 sample photographs the
// exhaustive search found 12 boards, the plain one all 13), then refines its
// corners with cv::cornerSubPix. Measured on the 20 synthetic views of
// tests/calib: the SB corners alone are about 0.17 px RMS from the truth
// (0.145 px with CALIB_CB_ACCURACY, at three times the time), the refined ones
// 0.077 px; on OpenCV's sample photographs the calibration's RMS falls from
// 0.26 px to 0.18 px (refined with or without CALIB_CB_ACCURACY alike). So
// CALIB_CB_ACCURACY is not used. When SB finds nothing, the classic
// cv::findChessboardCorners with the same refinement is tried, with its fast
// check (on a 640 x 480 image of noise it takes 9 s without, 0.1 s with), so
// that a frame without a board costs about 0.3 s in all.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

namespace nadir::calib {

struct BoardSpec {
  int inner_cols = 9;  // inner corners along a row of the board
  int inner_rows = 6;  // inner corners along a column
  double square_m = 0.025;

  cv::Size patternSize() const { return {inner_cols, inner_rows}; }
  int cornerCount() const { return inner_cols * inner_rows; }
};

// "9x6" (inner corners, cols x rows; 'x' or 'X') with the square's side.
// Throws std::invalid_argument naming the text and what is wrong.
BoardSpec parseBoardSpec(std::string_view cols_x_rows, double square_m);
// Throws std::invalid_argument unless both counts are >= 3 (OpenCV's detectors
// need that) and square_m is positive and finite.
void validateBoard(const BoardSpec& board);
// "9x6, 0.025 m squares"
std::string describeBoard(const BoardSpec& board);

// The inner corners in the board frame (metres, z = 0), row-major: corner
// (row r, col c) at index r * inner_cols + c is (c * square_m, r * square_m, 0),
// the order in which the detectors return image corners.
std::vector<cv::Point3f> boardObjectPoints(const BoardSpec& board);

enum class Detector {
  kSectorBased,            // cv::findChessboardCornersSB, normalised image
  kSectorBasedExhaustive,  // the same with CALIB_CB_EXHAUSTIVE
  kClassic,                // cv::findChessboardCorners
};
const char* detectorName(Detector detector);

struct Detection {
  // Level-0 pixels, row-major as boardObjectPoints, in canonical order
  // (canonicalCornerOrder).
  std::vector<cv::Point2f> corners_px;
  Detector detector = Detector::kSectorBased;
  // Width of the black-to-white rise (10 % to 90 %) across the board's edges,
  // px: cv::estimateChessboardSharpness, the larger of its horizontal and
  // vertical figures (motion blur smears one direction). A sharp photograph
  // gives 2.5 to 3.3 px, the same blurred with a sigma 3 px Gaussian 8 px.
  double sharpness_px = 0.0;
};

struct DetectOptions {
  // Images whose longer side exceeds this are searched at a scale that
  // brings it to this size (ROS's camera_calibration searches at VGA size),
  // and the corners refined at full resolution; if the board is not found
  // there, the full image is searched too. 0: always full resolution.
  int search_side_px = 640;
};

// Finds the whole board in an 8-bit grey or BGR(A) image; nothing when it is
// not there. Throws std::invalid_argument for an empty image or another pixel
// type, or an invalid board.
std::optional<Detection> detectBoard(const cv::Mat& gray_or_bgr, const BoardSpec& board,
                                     const DetectOptions& options = {});

// Reorders a row-major grid so that views of one board agree: of the grid's
// orderings that are rotations of it (the list reversed; for a square grid
// also the quarter turns), the one whose first corner is nearest the image's
// top-left pixel. The detectors may return any of them.
void canonicalCornerOrder(std::vector<cv::Point2f>& corners_px, const BoardSpec& board);

// cv::cornerSubPix with a half-window of 0.35 times the shortest distance
// between neighbouring corners (2 to 10 px), so the window never reaches the
// next corner on small or steeply tilted boards.
void refineCorners(const cv::Mat& gray, std::vector<cv::Point2f>& corners_px,
                   const BoardSpec& board);

}  // namespace nadir::calib
