#include "calib/session.h"

#include <stdexcept>
#include <utility>

namespace nadir::calib {
namespace {

std::string sizeText(cv::Size size) {
  return std::to_string(size.width) + "x" + std::to_string(size.height);
}

}  // namespace

CalibrationSession::CalibrationSession(const BoardSpec& board, const CoverageOptions& coverage)
    : board_(board), coverage_options_(coverage) {
  validateBoard(board_);
}

bool CalibrationSession::sizeFits(cv::Size image_size) {
  if (image_size_.area() == 0) image_size_ = image_size;
  return image_size == image_size_;
}

Offer CalibrationSession::offer(const cv::Mat& image, const std::string& name, bool auto_capture) {
  Offer result;
  ++tally_.offered;
  if (!image.empty() && !sizeFits(image.size())) {
    ++tally_.other_size;
    result.verdict.refusal = ViewRefusal::kOtherSize;
    result.verdict.reason = "other size: the image is " + sizeText(image.size()) +
                            ", the views before it " + sizeText(image_size_);
    return result;
  }
  result.detection = detectBoard(image, board_);
  result.verdict =
      isGoodView(result.detection, board_, image.size(), view_params_, coverage_options_);
  last_refusal_ = ViewRefusal::kNone;
  switch (result.verdict.refusal) {
    case ViewRefusal::kNoBoard:
      ++tally_.no_board;
      return result;
    case ViewRefusal::kBlurred:
      ++tally_.blurred;
      last_refusal_ = ViewRefusal::kBlurred;
      return result;
    case ViewRefusal::kDuplicate:
      // Without auto-capture the view adds no coverage but is not refused:
      // capture() may still keep it.
      if (!auto_capture) return result;
      ++tally_.duplicate;
      last_refusal_ = ViewRefusal::kDuplicate;
      return result;
    case ViewRefusal::kOtherSize:
    case ViewRefusal::kNone:
      break;
  }
  if (auto_capture) {
    views_.push_back({result.detection->corners_px, name});
    view_params_.push_back(result.verdict.params);
    ++tally_.kept;
    result.kept = true;
  }
  return result;
}

bool CalibrationSession::capture(const Detection& detection, const std::string& name,
                                 cv::Size image_size) {
  if (!sizeFits(image_size)) return false;
  if (static_cast<int>(detection.corners_px.size()) != board_.cornerCount()) return false;
  if (last_refusal_ == ViewRefusal::kBlurred) --tally_.blurred;
  if (last_refusal_ == ViewRefusal::kDuplicate) --tally_.duplicate;
  last_refusal_ = ViewRefusal::kNone;
  views_.push_back({detection.corners_px, name});
  view_params_.push_back(calib::viewParams(detection.corners_px, board_, image_size));
  ++tally_.kept;
  return true;
}

void CalibrationSession::removeView(int i) {
  if (i < 0 || i >= static_cast<int>(views_.size()))
    throw std::out_of_range("removeView: no kept view " + std::to_string(i));
  views_.erase(views_.begin() + i);
  view_params_.erase(view_params_.begin() + i);
  --tally_.kept;
}

void CalibrationSession::clear() {
  views_.clear();
  view_params_.clear();
  tally_ = {};
  image_size_ = {};
  last_refusal_ = ViewRefusal::kNone;
}

Coverage CalibrationSession::coverage() const {
  return calib::coverage(view_params_, coverage_options_);
}

Calibration CalibrationSession::calibrate(const CalibOptions& options) const {
  if (views_.size() < 3)
    throw std::invalid_argument("calibration needs at least 3 views of the " +
                                describeBoard(board_) + " board; " + std::to_string(views_.size()) +
                                " kept");
  return calib::calibrate(views_, board_, image_size_, options);
}

}  // namespace nadir::calib
