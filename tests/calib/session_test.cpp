// The calibration session: which offered images become views, and a tally
// that adds up to the images offered whatever the user captures or removes.

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "calib/report.h"
#include "calib/session.h"
#include "opencv_photos.h"

namespace nadir::calib {
namespace {

const BoardSpec kBoard{.inner_cols = 9, .inner_rows = 6, .square_m = 0.025};

int refused(const OfferTally& t) { return t.no_board + t.blurred + t.duplicate + t.other_size; }

// The same photograph twice: kept, then refused as adding no coverage; an
// image of another size and a blank one are refused with their reasons; the
// tally adds up.
TEST(Session, OffersAreKeptOrRefusedWithAReason) {
  CalibrationSession session(kBoard);
  const cv::Mat photo = test::loadPhoto("left01");
  EXPECT_TRUE(session.offer(photo, "a", true).kept);
  const Offer again = session.offer(photo, "b", true);
  EXPECT_FALSE(again.kept);
  EXPECT_EQ(again.verdict.refusal, ViewRefusal::kDuplicate);
  EXPECT_NE(again.verdict.reason.find("by 0.00 (needs more than 0.20)"), std::string::npos)
      << again.verdict.reason;
  cv::Mat half;
  cv::resize(photo, half, cv::Size(320, 240));
  const Offer small = session.offer(half, "c", true);
  EXPECT_EQ(small.verdict.refusal, ViewRefusal::kOtherSize);
  EXPECT_EQ(small.verdict.reason, "other size: the image is 320x240, the views before it 640x480");
  const Offer blank = session.offer(cv::Mat(480, 640, CV_8UC1, cv::Scalar(128)), "d", true);
  EXPECT_EQ(blank.verdict.refusal, ViewRefusal::kNoBoard);
  const OfferTally& t = session.tally();
  EXPECT_EQ(t.offered, 4);
  EXPECT_EQ(t.kept, 1);
  EXPECT_EQ(t.duplicate, 1);
  EXPECT_EQ(t.other_size, 1);
  EXPECT_EQ(t.no_board, 1);
  EXPECT_EQ(session.views().size(), 1u);
}

// Capturing a view auto-capture refused moves it from the refusals to the
// kept views; removing a view takes it out of the kept ones.
TEST(Session, CaptureAndRemoveKeepTheTallyWhole) {
  CalibrationSession session(kBoard);
  const cv::Mat photo = test::loadPhoto("left02");
  session.offer(photo, "first", true);
  const Offer duplicate = session.offer(photo, "second", true);
  ASSERT_EQ(duplicate.verdict.refusal, ViewRefusal::kDuplicate);
  ASSERT_TRUE(session.capture(*duplicate.detection, "second", photo.size()));
  EXPECT_EQ(session.tally().kept, 2);
  EXPECT_EQ(session.tally().duplicate, 0);
  EXPECT_EQ(session.tally().kept + refused(session.tally()), session.tally().offered);
  session.removeView(0);
  EXPECT_EQ(session.views().size(), 1u);
  EXPECT_EQ(session.views()[0].name, "second");
  EXPECT_EQ(session.tally().kept, 1);
  EXPECT_THROW(session.removeView(1), std::out_of_range);
  // A detection of another size is not kept.
  EXPECT_FALSE(session.capture(*duplicate.detection, "third", cv::Size(320, 240)));
  EXPECT_EQ(session.views().size(), 1u);
}

// Fewer than three views: calibrate says how many there are.
TEST(Session, CalibrateNeedsThreeViews) {
  CalibrationSession session(kBoard);
  session.offer(test::loadPhoto("left01"), "a", true);
  session.offer(test::loadPhoto("left02"), "b", true);
  try {
    session.calibrate({});
    FAIL() << "calibrated two views";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("at least 3 views"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("2 kept"), std::string::npos);
  }
}

// The coverage bars: a progress of 0.5 fills half of a 20-cell bar.
TEST(Session, ProgressBars) {
  EXPECT_EQ(progressBar(0.5, 10), "[#####-----]");
  EXPECT_EQ(progressBar(0.0, 4), "[----]");
  EXPECT_EQ(progressBar(1.7, 4), "[####]");
  EXPECT_EQ(progressBar(std::nan(""), 4), "[----]");
}

}  // namespace
}  // namespace nadir::calib
