// The feature VO's debug image: tracked features are green boxes, others dots,
// the status line sits on a black band at the top; bad frames are refused.

#include "nodes/vo_feature/debug_image.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace nadir::vo {
namespace {

TEST(DebugImage, TrackedFeaturesAreGreenBoxesOthersAreDots) {
  const cv::Mat gray(480, 640, CV_8UC1, cv::Scalar(128));
  const std::vector<DebugFeature> features{{cv::Point2f(300.0f, 300.0f), 0, true},
                                           {cv::Point2f(500.0f, 400.0f), 1, false}};
  const cv::Mat rgb = drawDebugImage(gray, features, "TRACKING");
  ASSERT_EQ(rgb.type(), CV_8UC3);
  ASSERT_EQ(rgb.size(), gray.size());
  // The box of the tracked feature: 2 px from its centre (640 / 320), pure green on its edge.
  const cv::Vec3b edge = rgb.at<cv::Vec3b>(300, 302);
  EXPECT_LT(edge[0], 100);
  EXPECT_GT(edge[1], 200);
  // The untracked feature's dot is blue-ish (R first), no box around it.
  const cv::Vec3b dot = rgb.at<cv::Vec3b>(400, 500);
  EXPECT_GT(dot[2], dot[0]);
  EXPECT_EQ(rgb.at<cv::Vec3b>(400, 503), cv::Vec3b(128, 128, 128));
  // The status band is black at its left edge, the rest of the frame untouched.
  EXPECT_EQ(rgb.at<cv::Vec3b>(2, 1), cv::Vec3b(0, 0, 0));
  EXPECT_EQ(rgb.at<cv::Vec3b>(200, 100), cv::Vec3b(128, 128, 128));
}

TEST(DebugImage, RefusesFramesItCannotDraw) {
  EXPECT_THROW(drawDebugImage(cv::Mat(), {}, "x"), std::invalid_argument);
  EXPECT_THROW(drawDebugImage(cv::Mat(10, 10, CV_32FC1), {}, "x"), std::invalid_argument);
  EXPECT_THROW(drawDebugImage(cv::Mat(10, 10, CV_8UC2), {}, "x"), std::invalid_argument);
}

}  // namespace
}  // namespace nadir::vo
