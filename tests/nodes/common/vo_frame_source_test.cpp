// VoFrameSource on an in-process bus: no frame before the lens and the truth;
// the start pose is the truth's newest pose before the first image, not its
// first message; an image of the wrong size is refused with the reason; the
// range and the camera's mount reach the frame.
#include "nodes/common/vo_frame_source.h"

#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <string>
#include <variant>

#include "core/bus.h"
#include "core/frames.h"
#include "lcmtypes/bus_io.h"

namespace nadir::nodes {
namespace {

const VoFrameSourceChannels kChannels{.info_channel = "INFO",
                                      .range_channel = "RANGE",
                                      .attitude_channel = "ATTITUDE",
                                      .truth_channel = "TRUTH"};

class VoFrameSourceTest : public ::testing::Test {
 protected:
  void truth(std::int64_t utime, double north_m) {
    msg::Pose pose;
    pose.utime = utime;
    pose.p_ned_m = Eigen::Vector3d(north_m, 0.0, -100.0);
    msg::publish(*bus_, kChannels.truth_channel, pose);
    bus_->handleAvailable();
  }
  void lens() {
    msg::CameraInfo info;
    info.width = 64;
    info.height = 48;
    info.fx = info.fy = 50.0;
    info.cx = 32.0;
    info.cy = 24.0;
    info.q_body_cam = Eigen::Quaterniond(core::rotationBodyFromDownCamera());
    msg::publish(*bus_, kChannels.info_channel, info);
    msg::Range range;
    range.range_m = 100.0;
    range.status = msg::RangeStatus::VALID;
    range.max_range_m = 1000.0;
    msg::publish(*bus_, kChannels.range_channel, range);
    bus_->handleAvailable();
  }
  msg::Image image(std::int64_t utime, int width = 64) {
    return msg::Image{utime, cv::Mat(48, width, CV_8UC1, cv::Scalar(100)), 0, {}};
  }

  std::unique_ptr<core::Bus> bus_ = core::openBus("memq://");
  std::optional<Eigen::Isometry3d> start_;
  int starts_ = 0;
  VoFrameSource source_{*bus_, kChannels, [this](const Eigen::Isometry3d& T_world_body) {
                          start_ = T_world_body;
                          ++starts_;
                        }};
};

TEST_F(VoFrameSourceTest, StartsAtTheTruthOfTheFirstImage) {
  // Nothing before the lens and the truth: an empty reason, not a drop.
  auto made = source_.frame(image(0), false);
  ASSERT_TRUE(std::holds_alternative<std::string>(made));
  EXPECT_TRUE(std::get<std::string>(made).empty());
  lens();
  made = source_.frame(image(0), false);
  EXPECT_TRUE(std::get<std::string>(made).empty());
  EXPECT_EQ(starts_, 0);

  // The truth at 400 Hz from t = 0, 25 m/s north; the first image at 32.5 ms
  // starts at the newest pose before it (30 ms: 0.75 m north), not at 0 m.
  for (int k = 0; k <= 12; ++k) truth(2500 * k, 25.0 * 0.0025 * k);
  made = source_.frame(image(32500), false);
  ASSERT_TRUE(std::holds_alternative<vo::VoFrameInput>(made));
  ASSERT_EQ(starts_, 1);
  EXPECT_NEAR(start_->translation().x(), 0.75, 1e-9);
  const vo::VoFrameInput& frame = std::get<vo::VoFrameInput>(made);
  EXPECT_EQ(frame.utime, 32500);
  EXPECT_DOUBLE_EQ(*frame.range_m, 100.0);
  EXPECT_TRUE(frame.R_body_cam.isApprox(core::rotationBodyFromDownCamera()));
  EXPECT_DOUBLE_EQ(frame.K(0, 0), 50.0);

  // Later truth does not start it again.
  truth(40000, 1.0);
  source_.frame(image(64500), false);
  EXPECT_EQ(starts_, 1);

  // An image of another size is refused with the sizes named.
  made = source_.frame(image(97000, 80), false);
  ASSERT_TRUE(std::holds_alternative<std::string>(made));
  EXPECT_NE(std::get<std::string>(made).find("80x48"), std::string::npos);
  EXPECT_NE(std::get<std::string>(made).find("64x48"), std::string::npos);
}

}  // namespace
}  // namespace nadir::nodes
