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

// Whether the checker pattern goes on past the detected grid: then the grid is
// part of a larger board (findChessboardCornersSB finds a 7x5 grid inside a
// 9x6 board). The squares just outside the outer corners alternate on any
// board; one square farther out lies the board's margin for the whole board,
// more alternating squares for a part of it. Sampled through the homography
// of the corners (local enough to ignore the lens). On OpenCV's sample
// photographs the step one square out is 0.21-0.56 of the outer squares' for
// the whole 9x6 board (a cluttered background behind a narrow margin), 0.95
// and 2.9 for the two 7x5 parts found in them: the line is drawn at 0.8.
bool gridContinues(const cv::Mat& gray, const std::vector<cv::Point2f>& corners,
                   const BoardSpec& board) {
  const int cols = board.inner_cols, rows = board.inner_rows;
  std::vector<cv::Point2f> grid;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) grid.emplace_back(static_cast<float>(c), static_cast<float>(r));
  const cv::Mat H = cv::findHomography(grid, corners);
  if (H.empty()) return false;
  // Mean absolute step between neighbouring square centres along a ring at
  // offset d squares outside the corners (d = 0.5: the board's outer squares).
  const auto ringContrast = [&](double d) {
    std::vector<cv::Point2f> ring;
    for (int c = -1; c < cols; ++c) ring.emplace_back(c + 0.5f, static_cast<float>(-d));
    for (int r = -1; r < rows; ++r) ring.emplace_back(static_cast<float>(cols - 1 + d), r + 0.5f);
    for (int c = cols - 1; c >= 0; --c)
      ring.emplace_back(c - 0.5f, static_cast<float>(rows - 1 + d));
    for (int r = rows - 1; r >= 0; --r) ring.emplace_back(static_cast<float>(-d), r - 0.5f);
    std::vector<cv::Point2f> pixels;
    cv::perspectiveTransform(ring, pixels, H);
    double sum = 0.0;
    int steps = 0;
    for (std::size_t i = 0; i + 1 < pixels.size(); ++i) {
      const cv::Point2f& a = pixels[i];
      const cv::Point2f& b = pixels[i + 1];
      const cv::Rect inside(0, 0, gray.cols, gray.rows);
      if (!inside.contains(cv::Point(a)) || !inside.contains(cv::Point(b))) continue;
      sum += std::abs(double(gray.at<std::uint8_t>(cv::Point(a))) -
                      double(gray.at<std::uint8_t>(cv::Point(b))));
      ++steps;
    }
    return steps >= 4 ? sum / steps : 0.0;
  };
  const double outer_squares = ringContrast(0.5);
  const double beyond = ringContrast(1.5);
  return outer_squares > 0.0 && beyond > 0.8 * outer_squares;
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

namespace {

// The detectors in turn on one image; corners in its pixels.
std::optional<Detection> findBoard(const cv::Mat& gray, const BoardSpec& board) {
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
  return detection;
}

}  // namespace

std::optional<Detection> detectBoard(const cv::Mat& gray_or_bgr, const BoardSpec& board,
                                     const DetectOptions& options) {
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

  const cv::Size pattern = board.patternSize();
  const int longer_side = std::max(gray.cols, gray.rows);
  std::optional<Detection> found;
  if (options.search_side_px > 0 && longer_side > options.search_side_px) {
    const double scale = static_cast<double>(longer_side) / options.search_side_px;
    cv::Mat small;
    cv::resize(gray, small,
               cv::Size(static_cast<int>(std::lround(gray.cols / scale)),
                        static_cast<int>(std::lround(gray.rows / scale))),
               0, 0, cv::INTER_AREA);
    found = findBoard(small, board);
    if (found) {
      // Pixel centres: small pixel u covers full pixels around (u + 0.5) s - 0.5.
      const float sx = static_cast<float>(gray.cols) / small.cols;
      const float sy = static_cast<float>(gray.rows) / small.rows;
      for (cv::Point2f& p : found->corners_px) {
        p.x = (p.x + 0.5f) * sx - 0.5f;
        p.y = (p.y + 0.5f) * sy - 0.5f;
      }
    }
  }
  if (!found) found = findBoard(gray, board);
  if (!found) return std::nullopt;
  Detection detection = std::move(*found);
  refineCorners(gray, detection.corners_px, board);
  if (gridContinues(gray, detection.corners_px, board)) return std::nullopt;
  canonicalCornerOrder(detection.corners_px, board);
  const cv::Scalar horizontal =
      cv::estimateChessboardSharpness(gray, pattern, detection.corners_px, 0.8f, false);
  const cv::Scalar vertical =
      cv::estimateChessboardSharpness(gray, pattern, detection.corners_px, 0.8f, true);
  detection.sharpness_px = std::max(horizontal[0], vertical[0]);
  return detection;
}

}  // namespace nadir::calib
