#pragma once
// A calibration in progress, as nadir calib and the nadir-calib window run it:
// images offered one at a time, the board looked for in each, a view kept
// when it adds coverage (auto-capture) or when the user asks (capture), and
// the kept views calibrated.

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "calib/board.h"
#include "calib/calibrate.h"
#include "calib/coverage.h"

namespace nadir::calib {

struct Offer {
  std::optional<Detection> detection;
  // Why the view was not kept (kNone when it was, or when auto-capture was off
  // and the board was found: the view waits for capture()).
  ViewVerdict verdict;
  bool kept = false;
};

// How the offered images fared, for the report.
struct OfferTally {
  int offered = 0;
  int no_board = 0;
  int blurred = 0;
  int duplicate = 0;
  int other_size = 0;
  int kept = 0;
};

class CalibrationSession {
 public:
  // Throws std::invalid_argument for an invalid board.
  explicit CalibrationSession(const BoardSpec& board, const CoverageOptions& coverage = {});

  // Looks for the board in an 8-bit grey or BGR image. With auto_capture the
  // view is kept when isGoodView says so; without, a found board is only
  // reported (capture() keeps it). An image of another size than the first
  // one offered is refused (kOtherSize). Throws std::invalid_argument for an
  // empty image or another pixel type.
  Offer offer(const cv::Mat& image, const std::string& name, bool auto_capture);

  // Keeps the view last offered, whatever its coverage or sharpness (the
  // user's capture): its refusal, if any, leaves the tally. Returns false
  // (keeping nothing) for an image of another size or a detection of another
  // board.
  bool capture(const Detection& detection, const std::string& name, cv::Size image_size);

  // Forgets kept view i (0 <= i < views().size()); throws std::out_of_range
  // for another i.
  void removeView(int i);
  void clear();

  const BoardSpec& board() const { return board_; }
  const CoverageOptions& coverageOptions() const { return coverage_options_; }
  // The size of the first image offered or captured; 0 x 0 before.
  cv::Size imageSize() const { return image_size_; }
  const std::vector<View>& views() const { return views_; }
  const std::vector<ViewParams>& viewParams() const { return view_params_; }
  Coverage coverage() const;
  const OfferTally& tally() const { return tally_; }

  // Calibrates the kept views. Throws std::invalid_argument naming how many
  // views there are when fewer than 3 are kept.
  Calibration calibrate(const CalibOptions& options) const;

 private:
  bool sizeFits(cv::Size image_size);

  BoardSpec board_;
  CoverageOptions coverage_options_;
  cv::Size image_size_;
  std::vector<View> views_;
  std::vector<ViewParams> view_params_;
  OfferTally tally_;
  // The refusal of the view last offered, until capture() takes it back.
  ViewRefusal last_refusal_ = ViewRefusal::kNone;
};

}  // namespace nadir::calib
