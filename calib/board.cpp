#include "calib/board.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace nadir::calib {
namespace {

// A whole positive number, nothing else.
std::optional<int> parseCount(std::string_view text) {
  if (text.empty()) return std::nullopt;
  int value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

double shortestNeighbourSpacing_px(const std::vector<cv::Point2f>& corners,
                                   const BoardSpec& board) {
  double shortest = std::numeric_limits<double>::infinity();
  for (int r = 0; r < board.inner_rows; ++r) {
    for (int c = 0; c < board.inner_cols; ++c) {
      const cv::Point2f& p = corners[r * board.inner_cols + c];
      if (c + 1 < board.inner_cols)
        shortest = std::min(shortest, cv::norm(p - corners[r * board.inner_cols + c + 1]));
      if (r + 1 < board.inner_rows)
        shortest = std::min(shortest, cv::norm(p - corners[(r + 1) * board.inner_cols + c]));
    }
  }
  return shortest;
}

}  // namespace

BoardSpec parseBoardSpec(std::string_view cols_x_rows, double square_m) {
  const std::size_t x = cols_x_rows.find_first_of("xX");
  const std::string quoted = "board '" + std::string(cols_x_rows) + "'";
  if (x == std::string_view::npos)
    throw std::invalid_argument(quoted + ": expected COLSxROWS of inner corners, e.g. 9x6");
  const std::optional<int> cols = parseCount(cols_x_rows.substr(0, x));
  const std::optional<int> rows = parseCount(cols_x_rows.substr(x + 1));
  if (!cols)
    throw std::invalid_argument(
        quoted + ": the inner corners per row (before the x) are not a whole number");
  if (!rows)
    throw std::invalid_argument(
        quoted + ": the inner corners per column (after the x) are not a whole number");
  BoardSpec board{.inner_cols = *cols, .inner_rows = *rows, .square_m = square_m};
  try {
    validateBoard(board);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(quoted + ": " + e.what());
  }
  return board;
}

void validateBoard(const BoardSpec& board) {
  if (board.inner_cols < 3)
    throw std::invalid_argument("inner_cols = " + std::to_string(board.inner_cols) +
                                ": a board needs at least 3 inner corners per row");
  if (board.inner_rows < 3)
    throw std::invalid_argument("inner_rows = " + std::to_string(board.inner_rows) +
                                ": a board needs at least 3 inner corners per column");
  if (!(board.square_m > 0.0) || !std::isfinite(board.square_m)) {
    std::ostringstream out;
    out << "square_m = " << board.square_m << ": the square's side must be a positive length";
    throw std::invalid_argument(out.str());
  }
}

std::string describeBoard(const BoardSpec& board) {
  std::ostringstream out;
  out << board.inner_cols << "x" << board.inner_rows << ", " << board.square_m << " m squares";
  return out.str();
}

std::vector<cv::Point3f> boardObjectPoints(const BoardSpec& board) {
  validateBoard(board);
  std::vector<cv::Point3f> points;
  points.reserve(board.cornerCount());
  for (int r = 0; r < board.inner_rows; ++r) {
    for (int c = 0; c < board.inner_cols; ++c)
      points.emplace_back(static_cast<float>(c * board.square_m),
                          static_cast<float>(r * board.square_m), 0.0f);
  }
  return points;
}

const char* detectorName(Detector detector) {
  switch (detector) {
    case Detector::kSectorBased:
      return "findChessboardCornersSB";
    case Detector::kSectorBasedExhaustive:
      return "findChessboardCornersSB (exhaustive)";
    case Detector::kClassic:
      return "findChessboardCorners";
  }
  return "unknown";
}

void canonicalCornerOrder(std::vector<cv::Point2f>& corners_px, const BoardSpec& board) {
  const int cols = board.inner_cols, rows = board.inner_rows;
  if (static_cast<int>(corners_px.size()) != cols * rows)
    throw std::invalid_argument("canonicalCornerOrder: " + std::to_string(corners_px.size()) +
                                " corners for a " + describeBoard(board) + " board");
  // Each candidate maps the output index (r, c) to an input index.
  using Map = int (*)(int r, int c, int cols, int rows);
  std::vector<Map> candidates = {
      [](int r, int c, int n_cols, int) { return r * n_cols + c; },
      [](int r, int c, int n_cols, int n_rows) {
        return (n_rows - 1 - r) * n_cols + (n_cols - 1 - c);
      },
  };
  if (cols == rows) {
    // Quarter turns; only a square grid maps onto itself under them.
    candidates.push_back(
        [](int r, int c, int n_cols, int) { return (n_cols - 1 - c) * n_cols + r; });
    candidates.push_back(
        [](int r, int c, int n_cols, int) { return c * n_cols + (n_cols - 1 - r); });
  }
  std::size_t best = 0;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const cv::Point2f& first = corners_px[candidates[i](0, 0, cols, rows)];
    const double d2 = double(first.x) * first.x + double(first.y) * first.y;
    if (d2 < best_d2) {
      best_d2 = d2;
      best = i;
    }
  }
  if (best == 0) return;
  std::vector<cv::Point2f> reordered(corners_px.size());
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c)
      reordered[r * cols + c] = corners_px[candidates[best](r, c, cols, rows)];
  }
  corners_px = std::move(reordered);
}

void refineCorners(const cv::Mat& gray, std::vector<cv::Point2f>& corners_px,
                   const BoardSpec& board) {
  const double spacing = shortestNeighbourSpacing_px(corners_px, board);
  const int half = std::clamp(static_cast<int>(std::floor(0.35 * spacing)), 2, 10);
  cv::cornerSubPix(gray, corners_px, cv::Size(half, half), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4));
}

std::optional<Detection> detectBoard(const cv::Mat& gray_or_bgr, const BoardSpec& board) {
  validateBoard(board);
  if (gray_or_bgr.empty()) throw std::invalid_argument("detectBoard: the image is empty");
  if (gray_or_bgr.depth() != CV_8U ||
      (gray_or_bgr.channels() != 1 && gray_or_bgr.channels() != 3 && gray_or_bgr.channels() != 4))
    throw std::invalid_argument(
        "detectBoard: the image must be 8-bit grey, BGR or BGRA, not type " +
        std::to_string(gray_or_bgr.type()));
  cv::Mat gray;
  if (gray_or_bgr.channels() == 1)
    gray = gray_or_bgr;
  else
    cv::cvtColor(gray_or_bgr, gray,
                 gray_or_bgr.channels() == 3 ? cv::COLOR_BGR2GRAY : cv::COLOR_BGRA2GRAY);

  Detection detection;
  const cv::Size pattern = board.patternSize();
  if (cv::findChessboardCornersSB(gray, pattern, detection.corners_px,
                                  cv::CALIB_CB_NORMALIZE_IMAGE)) {
    detection.detector = Detector::kSectorBased;
  } else if (cv::findChessboardCornersSB(gray, pattern, detection.corners_px,
                                         cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_EXHAUSTIVE)) {
    detection.detector = Detector::kSectorBasedExhaustive;
  } else if (cv::findChessboardCorners(gray, pattern, detection.corners_px,
                                       cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE |
                                           cv::CALIB_CB_FAST_CHECK)) {
    detection.detector = Detector::kClassic;
  } else {
    return std::nullopt;
  }
  if (static_cast<int>(detection.corners_px.size()) != board.cornerCount()) return std::nullopt;
  refineCorners(gray, detection.corners_px, board);
  canonicalCornerOrder(detection.corners_px, board);
  const cv::Scalar horizontal =
      cv::estimateChessboardSharpness(gray, pattern, detection.corners_px, 0.8f, false);
  const cv::Scalar vertical =
      cv::estimateChessboardSharpness(gray, pattern, detection.corners_px, 0.8f, true);
  detection.sharpness_px = std::max(horizontal[0], vertical[0]);
  return detection;
}

}  // namespace nadir::calib
