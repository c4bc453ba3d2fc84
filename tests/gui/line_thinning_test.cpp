#include "gui/line_thinning.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace nadir::gui {
namespace {

using Indices = std::vector<std::size_t>;

// 100 000 samples of a flat line (x = 0, 1, ..., y = 0) with one spike of +50.
// The old thinning to every 25th point dropped it: 61234 is not a multiple of 25.
constexpr std::size_t kSamples = 100000;
constexpr std::size_t kSpike = 61234;

std::vector<PlotPoint> flatLineWithSpike() {
  std::vector<PlotPoint> points(kSamples);
  for (std::size_t i = 0; i < kSamples; ++i) points[i] = {static_cast<double>(i), 0.0};
  points[kSpike].y = 50.0;
  return points;
}

bool contains(const Indices& kept, std::size_t index) {
  return std::find(kept.begin(), kept.end(), index) != kept.end();
}

// The spike is kept over the whole line whatever the number of columns, and
// never more than 4 points per column (plus the two outside, none here).
TEST(LineThinning, ASpikeIsKeptForAnyColumnCount) {
  const std::vector<PlotPoint> points = flatLineWithSpike();
  for (const int columns : {1, 2, 7, 100, 1000, 1920, 2000, 4096, 99999, 250000}) {
    const Indices kept =
        keptTimeSeriesPoints(points, 0.0, static_cast<double>(kSamples - 1), columns);
    EXPECT_TRUE(contains(kept, kSpike)) << columns;
    EXPECT_LE(kept.size(), 4 * static_cast<std::size_t>(columns) + 2) << columns;
    EXPECT_TRUE(std::is_sorted(kept.begin(), kept.end())) << columns;
    EXPECT_TRUE(std::adjacent_find(kept.begin(), kept.end()) == kept.end()) << columns;
    ASSERT_FALSE(kept.empty());
    EXPECT_EQ(kept.front(), 0u) << columns;  // the first column's first point
    EXPECT_EQ(kept.back(), kSamples - 1) << columns;
  }
}

// One column over the whole line: its first point (also its least y, the first
// of the zeros), the spike (its greatest) and its last point. Fewer than one
// column counts as one.
TEST(LineThinning, OneColumnKeepsFirstExtremesAndLast) {
  const std::vector<PlotPoint> points = flatLineWithSpike();
  const Indices expected = {0, kSpike, kSamples - 1};
  EXPECT_EQ(keptTimeSeriesPoints(points, 0.0, 99999.0, 1), expected);
  EXPECT_EQ(keptTimeSeriesPoints(points, 0.0, 99999.0, 0), expected);
}

// Worked by hand: x 0..7 over [0, 8] in 2 columns, so x 0-3 and 4-7.
// Column 0, y {0, 5, -3, 1}: first 0, greatest 1, least 2, last 3.
// Column 1, y {2, 2, 9, 2}: first 4 (also the least, the first of the 2s),
// greatest 6, last 7; index 5 is dropped.
TEST(LineThinning, EachColumnKeepsItsFirstLastLeastAndGreatest) {
  const std::vector<PlotPoint> points = {{0, 0}, {1, 5}, {2, -3}, {3, 1},
                                         {4, 2}, {5, 2}, {6, 9},  {7, 2}};
  EXPECT_EQ(keptTimeSeriesPoints(points, 0.0, 8.0, 2), (Indices{0, 1, 2, 3, 4, 6, 7}));
}

// A zoomed window [61000, 61500] in 100 columns of 5 samples (the last also
// holds x = 61500, 6 samples): each column keeps its first and last (the flat
// line's least and greatest are its first), the spike's column 46 (61230-61234)
// its first and the spike, which is also its last; plus the point before the
// window (60999) and the one after (61501): 1 + 100 * 2 + 1 = 202 points.
TEST(LineThinning, AZoomedWindowKeepsTheSpikeInsideItAndTheEdgePoints) {
  const std::vector<PlotPoint> points = flatLineWithSpike();
  const Indices kept = keptTimeSeriesPoints(points, 61000.0, 61500.0, 100);
  EXPECT_TRUE(contains(kept, kSpike));
  EXPECT_EQ(kept.size(), 202u);
  ASSERT_FALSE(kept.empty());
  EXPECT_EQ(kept.front(), 60999u);
  EXPECT_EQ(kept.back(), 61501u);
  EXPECT_TRUE(contains(kept, 61230u));
  EXPECT_TRUE(contains(kept, 61495u));  // the last column: 61495 to 61500
  EXPECT_TRUE(contains(kept, 61500u));
}

// A window away from the spike does not draw it: only its columns' points and
// the two just outside.
TEST(LineThinning, AWindowWithoutTheSpikeDoesNotKeepIt) {
  const std::vector<PlotPoint> points = flatLineWithSpike();
  const Indices kept = keptTimeSeriesPoints(points, 70000.0, 70500.0, 100);
  EXPECT_FALSE(contains(kept, kSpike));
  ASSERT_FALSE(kept.empty());
  EXPECT_EQ(kept.front(), 69999u);
  EXPECT_EQ(kept.back(), 70501u);
}

// A window between two samples keeps just those two: the line crosses the view.
// A window past the end keeps the last point, one before the start the first.
TEST(LineThinning, AWindowBetweenSamplesKeepsTheTwoAroundIt) {
  const std::vector<PlotPoint> points = flatLineWithSpike();
  EXPECT_EQ(keptTimeSeriesPoints(points, 100.25, 100.75, 1000), (Indices{100, 101}));
  EXPECT_EQ(keptTimeSeriesPoints(points, 200000.0, 300000.0, 1000), (Indices{kSamples - 1}));
  EXPECT_EQ(keptTimeSeriesPoints(points, -300.0, -200.0, 1000), (Indices{0}));
}

// A point with a non-finite value is never kept: with index 0 NaN, the one
// column's first is 1 (least y 1), greatest 2 (y 5), last 4.
TEST(LineThinning, NonFinitePointsAreNotKept) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<PlotPoint> points = {{0, nan}, {1, 1}, {2, 5}, {3, 2}, {4, 3}};
  EXPECT_EQ(keptTimeSeriesPoints(points, 0.0, 4.0, 1), (Indices{1, 2, 4}));
}

// Worked by hand with tolerance 1 on both axes: (0.4, 0) and (0.8, 0) are within
// 1 of (0, 0); (1.2, 0) is not; (1.2, 0.3) is within 1 of it; (1.2, 2) is 2 up;
// (0, 0) is the last point.
TEST(PathThinning, KeepsAPointFurtherThanTheToleranceFromTheLastKept) {
  const std::vector<PlotPoint> path = {{0, 0},     {0.4, 0}, {0.8, 0}, {1.2, 0},
                                       {1.2, 0.3}, {1.2, 2}, {0, 0}};
  EXPECT_EQ(keptPathPoints(path, 1.0, 1.0), (Indices{0, 3, 5, 6}));
}

// A path along east at 0.01 m steps, with a 3 m excursion north peaking at
// (50, 3) m, thinned to 0.05 m: a point within the tolerance of the tip is kept,
// and every point of the path lies within it of the kept point before it (the
// bound the header states), checked point by point.
TEST(PathThinning, AnExcursionsTipIsKeptWithinTheTolerance) {
  constexpr double kTolerance_m = 0.05;
  std::vector<PlotPoint> path;
  for (int i = 0; i <= 10000; ++i) {
    const double east_m = 0.01 * i;
    path.push_back({east_m, std::max(0.0, 3.0 - std::abs(east_m - 50.0))});
  }
  // Then back west along the line north of it: x is not monotonic.
  for (int i = 10000; i >= 0; --i) path.push_back({0.01 * i, 10.0});
  const Indices kept = keptPathPoints(path, kTolerance_m, kTolerance_m);
  ASSERT_FALSE(kept.empty());
  EXPECT_EQ(kept.front(), 0u);
  EXPECT_EQ(kept.back(), path.size() - 1);
  EXPECT_LT(kept.size(), path.size() / 4);  // about 1 point in 5 or 6 on a straight line
  bool tip_kept = false;
  for (const std::size_t i : kept) {
    tip_kept |=
        std::abs(path[i].x - 50.0) <= kTolerance_m && std::abs(path[i].y - 3.0) <= kTolerance_m;
  }
  EXPECT_TRUE(tip_kept);
  std::size_t anchor = 0;
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (std::binary_search(kept.begin(), kept.end(), i)) anchor = i;
    EXPECT_LE(std::abs(path[i].x - path[anchor].x), kTolerance_m) << i;
    EXPECT_LE(std::abs(path[i].y - path[anchor].y), kTolerance_m) << i;
  }
}

// Worked by hand in the view [0, 1] x [0, 1]: of the runs outside it, left
// (0-2), right (4-6), top right (7-9), top (10) and top left (11-12), only the
// first and last are kept; 1, 5 and 8 are dropped. 3 is in the view.
TEST(PathThinning, OfEachRunOutsideTheViewTheEndsAreKept) {
  const std::vector<PlotPoint> path = {{-3, 0.5}, {-2, 0.5}, {-1, 0.5}, {0.5, 0.5}, {2, 0.5},
                                       {3, 0.5},  {4, 0.5},  {4, 2},    {3, 3},     {2, 2},
                                       {0.5, 2},  {-1, 2},   {-2, 3}};
  EXPECT_EQ(pathPointsAboutView(path, 0.0, 1.0, 0.0, 1.0),
            (Indices{0, 2, 3, 4, 6, 7, 9, 10, 11, 12}));
}

// A path that leaves the view [0, 1] x [0, 1] to the left and comes back from the
// right around its top keeps the detour (not a line from 1 to 9 across the view):
// only 6, inside the run 5-7 above the view, is dropped.
TEST(PathThinning, ADetourAroundTheViewIsKept) {
  const std::vector<PlotPoint> path = {{0.5, 0.5}, {-1, 0.5}, {-2, 0.5}, {-2, 2},
                                       {-1, 3},    {0.5, 3},  {0.6, 4},  {0.7, 3},
                                       {2, 3},     {2, 0.5},  {0.5, 0.5}};
  EXPECT_EQ(pathPointsAboutView(path, 0.0, 1.0, 0.0, 1.0),
            (Indices{0, 1, 2, 3, 4, 5, 7, 8, 9, 10}));
}

// The flat line with its spike as a path, viewed over [61000, 61500] x [-10, 60]
// on 500 x 70 px (half a pixel: 0.5 on both axes, less than the 1 between
// samples): the 501 points in view, the spike among them, and the ends of the
// runs left (0, 60999) and right (61501, 99999) of it: 505. Viewed over
// [70000, 70500] the spike is inside the left run and dropped.
TEST(PathThinning, AZoomedViewKeepsThePointsInItAndTheEndsOutside) {
  const std::vector<PlotPoint> points = flatLineWithSpike();
  const Indices kept = keptPathPointsInView(points, {61000, 61500, -10, 60, 500, 70});
  EXPECT_EQ(kept.size(), 505u);
  EXPECT_TRUE(contains(kept, kSpike));
  EXPECT_TRUE(contains(kept, 60999u));
  EXPECT_TRUE(contains(kept, 61501u));
  ASSERT_FALSE(kept.empty());
  EXPECT_EQ(kept.front(), 0u);
  EXPECT_EQ(kept.back(), kSamples - 1);
  const Indices away = keptPathPointsInView(points, {70000, 70500, -10, 60, 500, 70});
  EXPECT_EQ(away.size(), 505u);
  EXPECT_FALSE(contains(away, kSpike));
}

}  // namespace
}  // namespace nadir::gui
