#pragma once
// Thinning a plotted line to the points that change its pixels, without Qt: a
// chart draws the points kept, re-thinned whenever its view changes, and a
// single sample far off the line (an error spike) is never left out.

#include <cstddef>
#include <span>
#include <vector>

namespace nadir::gui {

// One sample of a line, in the chart's data units.
struct PlotPoint {
  double x = 0;
  double y = 0;
};

// What a chart shows: its axes' ranges, on a plot area of width_px x height_px.
struct PlotView {
  double x_lo = 0;
  double x_hi = 0;
  double y_lo = 0;
  double y_hi = 0;
  int width_px = 1;
  int height_px = 1;
  bool operator==(const PlotView&) const = default;
};

// A time series (x increasing) thinned by "M4" aggregation: the visible range
// [x_lo, x_hi] is split into `columns` equal columns, and of the points in each
// the first, the last, the one of least y and the one of greatest y are kept.
// Outside the range only the last point before x_lo and the first after x_hi are
// kept, so that the line still reaches the chart's edges. With one column per pixel the kept points
// draw exactly the pixels of the whole line (a pixel column of a line is the span of its first,
// last, least and greatest point and the lines to its neighbours), at most 4 * columns + 2 points
// whatever the series' length. Returns the indices kept, increasing. columns < 1 counts as 1, a
// range of zero width is one column, and a point with a non-finite value is never kept.
std::vector<std::size_t> keptTimeSeriesPoints(std::span<const PlotPoint> points, double x_lo,
                                              double x_hi, int columns);

// A path whose x is not monotonic (the top view: east against north; every value
// finite) thinned by distance: the first and last point are kept, and any point
// further than tolerance_x along x or tolerance_y along y from the last point
// kept (half a pixel on each axis: its visible range / pixels / 2). Bound: every
// dropped point lies within the tolerances (per axis) of the kept point before
// it, so the whole path lies within them of the line drawn, and no excursion
// larger than them is hidden. Returns the indices kept, increasing.
std::vector<std::size_t> keptPathPoints(std::span<const PlotPoint> points, double tolerance_x,
                                        double tolerance_y);

// The points of a path that draw its part in the view [x_lo, x_hi] x [y_lo, y_hi]
// (edges included): every point in it and, of each run of consecutive points in
// one of the eight regions around it (left, top left, top, ...), the first and
// the last. A region is convex, so the line between those two stays in it and
// the view shows exactly what the whole path shows there. keptPathPoints then
// thins these, zoomed in, far fewer than the path. Returns the indices kept,
// increasing.
std::vector<std::size_t> pathPointsAboutView(std::span<const PlotPoint> points, double x_lo,
                                             double x_hi, double y_lo, double y_hi);

// The points of a path a chart draws in the view: pathPointsAboutView, thinned by
// keptPathPoints to half a pixel on each axis. Returns the indices kept,
// increasing.
std::vector<std::size_t> keptPathPointsInView(std::span<const PlotPoint> points,
                                              const PlotView& view);

}  // namespace nadir::gui
