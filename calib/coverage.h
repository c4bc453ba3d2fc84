#pragma once
// How much of the camera's view a set of board views covers, and whether a
// new view adds to it: the measures of ROS's camera_calibration
// (calibrator.py: get_parameters, is_good_sample, compute_goodenough), so
// that auto-capture keeps the views a ROS user would expect.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "calib/board.h"

namespace nadir::calib {

// One view's place in the parameter space, each about 0..1.
struct ViewParams {
  // The board's centre (mean of its corners) across the image, as a share of
  // the image shrunk by half the board's size on each side (ROS: a large
  // board cannot move far, and is not penalised for it): 0 = touching the
  // left (top) edge, 1 = the right (bottom) edge, clamped to 0..1.
  double x = 0.0;
  double y = 0.0;
  // sqrt(area of the outer corners' quadrilateral / image area).
  double size = 0.0;
  // 2 |pi/2 - angle at the top-right outer corner|, rad, capped at 1:
  // 0 = seen frontally, grows as the board tilts.
  double skew = 0.0;
};

// Throws std::invalid_argument if the corner count is not the board's or the
// image size is not positive.
ViewParams viewParams(const std::vector<cv::Point2f>& corners_px, const BoardSpec& board,
                      cv::Size image_size);
// Sum of the absolute differences of the four parameters (ROS's distance).
double paramDistance(const ViewParams& a, const ViewParams& b);

struct CoverageOptions {
  // Span each parameter must reach for full coverage: ROS's X 0.7, Y 0.7,
  // size 0.4, skew 0.5.
  double x_range = 0.7;
  double y_range = 0.7;
  double size_range = 0.4;
  double skew_range = 0.5;
  // A new view is kept only when it is farther than this from every kept
  // view (ROS: 0.2).
  double min_distance = 0.2;
  // Refuse a view whose edges rise over more than this, px (Detection::
  // sharpness_px). OpenCV calls < 3 px sharp; sharp photographs reach 3.3 px
  // and a sigma 3 px blur gives 8 px, so the line is drawn between.
  double max_sharpness_px = 5.0;
  // With this many kept views the collection is good enough even without full
  // coverage (ROS: 40).
  int enough_views = 40;
};

struct ParamCoverage {
  const char* name = "";
  double min = 0.0;
  double max = 0.0;
  // (max - min) / range, capped at 1; ROS's progress bar. For size and skew
  // the span starts at 0 (ROS does not reward small or frontal views).
  double progress = 0.0;
};

struct Coverage {
  std::array<ParamCoverage, 4> params;  // X, Y, size, skew
  int views = 0;
  bool good_enough = false;
};

Coverage coverage(const std::vector<ViewParams>& kept, const CoverageOptions& options = {});
// Every parameter at full progress, or at least enough_views views (ROS).
bool goodEnough(const std::vector<ViewParams>& kept, const CoverageOptions& options = {});

enum class ViewRefusal {
  kNone,       // kept
  kNoBoard,    // no detection
  kBlurred,    // sharpness_px above max_sharpness_px
  kDuplicate,  // too close to kept view nearest_view
  kOtherSize,  // the image's size is not the one of the views before it
};
const char* refusalName(ViewRefusal refusal);

struct ViewVerdict {
  ViewRefusal refusal = ViewRefusal::kNone;
  std::string reason;     // one line for the user; empty when kept
  ViewParams params;      // when there was a board
  int nearest_view = -1;  // index in kept of the closest view, -1 if none
  double nearest_distance = 0.0;
  bool keep() const { return refusal == ViewRefusal::kNone; }
};

// Auto-capture's test of a new view against the kept ones, in this order:
// no board, blurred, duplicate (ROS: kept only when its distance to every
// kept view exceeds min_distance).
ViewVerdict isGoodView(const std::optional<Detection>& detection, const BoardSpec& board,
                       cv::Size image_size, const std::vector<ViewParams>& kept,
                       const CoverageOptions& options = {});

}  // namespace nadir::calib
