#include "gui/line_thinning.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

namespace nadir::gui {

namespace {

// The points of one column seen so far: their first, last, least-y and
// greatest-y indices.
struct ColumnExtremes {
  std::size_t first = 0;
  std::size_t last = 0;
  std::size_t lowest = 0;
  std::size_t highest = 0;
};

// Appends a column's kept indices in index order, each once.
void appendColumn(const ColumnExtremes& column, std::vector<std::size_t>& kept) {
  std::array<std::size_t, 4> indices = {column.first, column.lowest, column.highest, column.last};
  std::sort(indices.begin(), indices.end());
  const auto end = std::unique(indices.begin(), indices.end());
  kept.insert(kept.end(), indices.begin(), end);
}

}  // namespace

std::vector<std::size_t> keptTimeSeriesPoints(std::span<const PlotPoint> points, double x_lo,
                                              double x_hi, int columns) {
  const int column_count = std::max(columns, 1);
  const double width = x_hi - x_lo;
  const double columns_per_unit = width > 0 ? column_count / width : 0.0;
  std::vector<std::size_t> kept;
  std::optional<std::size_t> last_before;
  std::optional<std::size_t> first_after;
  std::optional<ColumnExtremes> open;
  int open_column = -1;
  // One pass rather than a binary search for the range: a series whose x steps
  // back (a log out of order) is then drawn thinned, if less tightly, not wrong.
  for (std::size_t i = 0; i < points.size(); ++i) {
    const PlotPoint& point = points[i];
    if (!std::isfinite(point.x) || !std::isfinite(point.y)) continue;
    if (point.x < x_lo) {
      last_before = i;
      continue;
    }
    if (point.x > x_hi) {
      if (!first_after) first_after = i;
      continue;
    }
    if (last_before && kept.empty() && !open) kept.push_back(*last_before);
    const int column = std::clamp(static_cast<int>(std::floor((point.x - x_lo) * columns_per_unit)),
                                  0, column_count - 1);
    if (open && column != open_column) {
      appendColumn(*open, kept);
      open.reset();
    }
    if (!open) {
      open = ColumnExtremes{i, i, i, i};
      open_column = column;
      continue;
    }
    open->last = i;
    if (point.y < points[open->lowest].y) open->lowest = i;
    if (point.y > points[open->highest].y) open->highest = i;
  }
  if (open) appendColumn(*open, kept);
  // Nothing visible: the line still crosses the view from the point before it to
  // the one after.
  if (kept.empty() && last_before) kept.push_back(*last_before);
  if (first_after && (kept.empty() || kept.back() < *first_after)) kept.push_back(*first_after);
  return kept;
}

std::vector<std::size_t> keptPathPoints(std::span<const PlotPoint> points, double tolerance_x,
                                        double tolerance_y) {
  std::vector<std::size_t> kept;
  if (points.empty()) return kept;
  kept.push_back(0);
  for (std::size_t i = 1; i < points.size(); ++i) {
    const PlotPoint& anchor = points[kept.back()];
    if (std::abs(points[i].x - anchor.x) > tolerance_x ||
        std::abs(points[i].y - anchor.y) > tolerance_y) {
      kept.push_back(i);
    }
  }
  if (kept.back() != points.size() - 1) kept.push_back(points.size() - 1);
  return kept;
}

std::vector<std::size_t> pathPointsAboutView(std::span<const PlotPoint> points, double x_lo,
                                             double x_hi, double y_lo, double y_hi) {
  // The region of a point: -1, 0 or 1 along each axis (before, in, after the
  // view's range), 4 for the view itself.
  const auto region = [&](const PlotPoint& point) {
    const int column = point.x < x_lo ? 0 : point.x > x_hi ? 2 : 1;
    const int row = point.y < y_lo ? 0 : point.y > y_hi ? 2 : 1;
    return 3 * row + column;
  };
  constexpr int kInView = 4;
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const int here = region(points[i]);
    const bool run_starts = i == 0 || region(points[i - 1]) != here;
    const bool run_ends = i + 1 == points.size() || region(points[i + 1]) != here;
    if (here == kInView || run_starts || run_ends) kept.push_back(i);
  }
  return kept;
}

std::vector<std::size_t> keptPathPointsInView(std::span<const PlotPoint> points,
                                              const PlotView& view) {
  const std::vector<std::size_t> about =
      pathPointsAboutView(points, view.x_lo, view.x_hi, view.y_lo, view.y_hi);
  std::vector<PlotPoint> about_points;
  about_points.reserve(about.size());
  for (const std::size_t i : about) about_points.push_back(points[i]);
  const double tolerance_x = (view.x_hi - view.x_lo) / std::max(view.width_px, 1) / 2.0;
  const double tolerance_y = (view.y_hi - view.y_lo) / std::max(view.height_px, 1) / 2.0;
  std::vector<std::size_t> kept = keptPathPoints(about_points, tolerance_x, tolerance_y);
  for (std::size_t& index : kept) index = about[index];
  return kept;
}

}  // namespace nadir::gui
