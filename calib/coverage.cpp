#include "calib/coverage.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace nadir::calib {
namespace {

double cross(const cv::Point2d& a, const cv::Point2d& b) { return a.x * b.y - a.y * b.x; }

}  // namespace

ViewParams viewParams(const std::vector<cv::Point2f>& corners_px, const BoardSpec& board,
                      cv::Size image_size) {
  validateBoard(board);
  if (static_cast<int>(corners_px.size()) != board.cornerCount())
    throw std::invalid_argument("viewParams: " + std::to_string(corners_px.size()) +
                                " corners, the " + describeBoard(board) + " board has " +
                                std::to_string(board.cornerCount()));
  if (image_size.width <= 0 || image_size.height <= 0)
    throw std::invalid_argument("viewParams: image size " + std::to_string(image_size.width) + "x" +
                                std::to_string(image_size.height) + " is not positive");
  const int cols = board.inner_cols;
  const cv::Point2d up_left = corners_px.front();
  const cv::Point2d up_right = corners_px[cols - 1];
  const cv::Point2d down_right = corners_px.back();
  const cv::Point2d down_left = corners_px[corners_px.size() - cols];

  // Area of the quadrilateral from its diagonals.
  const double area = 0.5 * std::abs(cross(down_left - up_right, down_right - up_left));
  const cv::Point2d ab = up_left - up_right, cb = down_right - up_right;
  const double cos_angle = std::clamp(ab.dot(cb) / (cv::norm(ab) * cv::norm(cb)), -1.0, 1.0);
  const double angle = std::acos(cos_angle);

  cv::Point2d mean(0, 0);
  for (const cv::Point2f& p : corners_px) mean += cv::Point2d(p);
  mean *= 1.0 / static_cast<double>(corners_px.size());

  const double border = std::sqrt(area);
  const double w = image_size.width, h = image_size.height;
  ViewParams params;
  params.x = std::clamp((mean.x - border / 2) / (w - border), 0.0, 1.0);
  params.y = std::clamp((mean.y - border / 2) / (h - border), 0.0, 1.0);
  params.size = std::sqrt(area / (w * h));
  params.skew = std::min(1.0, 2.0 * std::abs(std::numbers::pi / 2 - angle));
  return params;
}

double paramDistance(const ViewParams& a, const ViewParams& b) {
  return std::abs(a.x - b.x) + std::abs(a.y - b.y) + std::abs(a.size - b.size) +
         std::abs(a.skew - b.skew);
}

Coverage coverage(const std::vector<ViewParams>& kept, const CoverageOptions& options) {
  Coverage result;
  result.views = static_cast<int>(kept.size());
  const std::array<const char*, 4> names = {"X", "Y", "Size", "Skew"};
  const std::array<double, 4> ranges = {options.x_range, options.y_range, options.size_range,
                                        options.skew_range};
  for (int i = 0; i < 4; ++i) result.params[i].name = names[i];
  if (kept.empty()) return result;
  auto value = [](const ViewParams& p, int i) {
    return std::array<double, 4>{p.x, p.y, p.size, p.skew}[i];
  };
  bool all_full = true;
  for (int i = 0; i < 4; ++i) {
    ParamCoverage& c = result.params[i];
    c.min = c.max = value(kept.front(), i);
    for (const ViewParams& p : kept) {
      c.min = std::min(c.min, value(p, i));
      c.max = std::max(c.max, value(p, i));
    }
    if (i >= 2) c.min = 0.0;
    c.progress = std::min(1.0, (c.max - c.min) / ranges[i]);
    all_full = all_full && c.progress >= 1.0;
  }
  result.good_enough = all_full || result.views >= options.enough_views;
  return result;
}

bool goodEnough(const std::vector<ViewParams>& kept, const CoverageOptions& options) {
  return coverage(kept, options).good_enough;
}

const char* refusalName(ViewRefusal refusal) {
  switch (refusal) {
    case ViewRefusal::kNone:
      return "kept";
    case ViewRefusal::kNoBoard:
      return "no board";
    case ViewRefusal::kBlurred:
      return "blurred";
    case ViewRefusal::kDuplicate:
      return "duplicate";
    case ViewRefusal::kOtherSize:
      return "other size";
  }
  return "unknown";
}

ViewVerdict isGoodView(const std::optional<Detection>& detection, const BoardSpec& board,
                       cv::Size image_size, const std::vector<ViewParams>& kept,
                       const CoverageOptions& options) {
  ViewVerdict verdict;
  if (!detection) {
    verdict.refusal = ViewRefusal::kNoBoard;
    verdict.reason = "no board: the " + describeBoard(board) + " board was not found";
    return verdict;
  }
  verdict.params = viewParams(detection->corners_px, board, image_size);
  for (std::size_t i = 0; i < kept.size(); ++i) {
    const double d = paramDistance(verdict.params, kept[i]);
    if (verdict.nearest_view < 0 || d < verdict.nearest_distance) {
      verdict.nearest_view = static_cast<int>(i);
      verdict.nearest_distance = d;
    }
  }
  std::ostringstream why;
  why << std::fixed << std::setprecision(2);
  if (!(detection->sharpness_px <= options.max_sharpness_px)) {
    verdict.refusal = ViewRefusal::kBlurred;
    why << "blurred: edges rise over " << detection->sharpness_px << " px (at most "
        << options.max_sharpness_px << " px)";
  } else if (verdict.nearest_view >= 0 && verdict.nearest_distance <= options.min_distance) {
    verdict.refusal = ViewRefusal::kDuplicate;
    why << "duplicate: differs from kept view " << verdict.nearest_view << " by "
        << verdict.nearest_distance << " (needs more than " << options.min_distance << ")";
  }
  verdict.reason = why.str();
  return verdict;
}

}  // namespace nadir::calib
