// The direct VO node on an in-process bus, fed a synthetic flight (the
// textured ground of tests/support/textured_ground.h, 150 m below): it tracks
// from the truth's first pose; RESETs on VO_COMMAND restart it from the pose
// they carry, or without one where it was, and count in num_resets; a RESET
// addressed to another node changes nothing.
#include "nodes/vo_direct/vo_direct_node.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <numbers>
#include <vector>

#include "core/bus.h"
#include "core/frames.h"
#include "lcmtypes/bus_io.h"
#include "tests/support/textured_ground.h"

namespace nadir::vo {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr int kWidth = 1280;
constexpr int kHeight = 960;
constexpr double kAltitudeM = 150.0;  // above the textured ground at z = 0
constexpr double kStepM = 1.93;       // a frame every 1.93 m (no whole-pixel shifts)
constexpr std::int64_t kFrameUs = 100000;
const cv::Matx33d kK(800, 0, 640, 0, 800, 480, 0, 0, 1);

Eigen::Isometry3d truthAt(int frame) {
  return test::bodyPose(Eigen::Vector3d(-150.0 + kStepM * frame, -60.0, -kAltitudeM), 0.0, 0.0,
                        0.0);
}

double angleDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() / kDeg;
}

Eigen::Isometry3d poseOf(const msg::VoEstimate& estimate) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = estimate.q_world_body.toRotationMatrix();
  T.translation() = estimate.p_ned_m;
  return T;
}

class VoDirectNodeTest : public ::testing::Test {
 protected:
  VoDirectNodeTest() {
    params_.wall_clock_timing = false;
    node_ = std::make_unique<VoDirectNode>(*bus_, params_);
    subscription_ = msg::subscribe<msg::VoEstimate>(
        *bus_, params_.pose_channel,
        [this](const msg::VoEstimate& estimate) { estimates_.push_back(estimate); });
    debug_subscription_ = msg::subscribe<msg::Image>(
        *bus_, params_.debug_channel, [this](const msg::Image& image) { debug_.push_back(image); });
    msg::CameraInfo info;
    info.width = kWidth;
    info.height = kHeight;
    info.fx = kK(0, 0);
    info.fy = kK(1, 1);
    info.cx = kK(0, 2);
    info.cy = kK(1, 2);
    info.q_body_cam = Eigen::Quaterniond(core::rotationBodyFromDownCamera());
    msg::publish(*bus_, params_.info_channel, info);
    msg::Pose start;
    start.p_ned_m = truthAt(0).translation();
    msg::publish(*bus_, params_.truth_channel, start);
    bus_->handleAvailable();
  }

  // Publishes frame i (its range first) and returns the estimate it made.
  msg::VoEstimate fly(int i) {
    Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity();
    T_body_cam.linear() = core::rotationBodyFromDownCamera();
    const std::int64_t utime = i * kFrameUs;
    msg::Range range;
    range.utime = utime;
    range.range_m = kAltitudeM;
    range.status = msg::RangeStatus::VALID;
    range.max_range_m = 1000.0;
    msg::publish(*bus_, params_.range_channel, range);
    msg::publish(
        *bus_, params_.image_channel,
        msg::Image{utime,
                   test::renderGround(truthAt(i) * T_body_cam, kK, cv::Size(kWidth, kHeight)),
                   0,
                   {}});
    const std::size_t before = estimates_.size();
    bus_->handleAvailable();
    EXPECT_EQ(estimates_.size(), before + 1) << "frame " << i;
    return estimates_.back();
  }

  void command(const std::string& target, const std::optional<Eigen::Isometry3d>& T_world_body) {
    msg::VoCommand reset;
    reset.target = target;
    if (T_world_body) {
      msg::Pose pose;
      pose.p_ned_m = T_world_body->translation();
      pose.q_world_body = Eigen::Quaterniond(T_world_body->linear());
      reset.initial_pose = pose;
    }
    msg::publish(*bus_, params_.command_channel, reset);
  }

  std::unique_ptr<core::Bus> bus_ = core::openBus("memq://");
  VoDirectNodeParams params_;
  std::unique_ptr<VoDirectNode> node_;
  core::Subscription subscription_;
  std::vector<msg::VoEstimate> estimates_;
  core::Subscription debug_subscription_;
  std::vector<msg::Image> debug_;
};

TEST_F(VoDirectNodeTest, TracksAndResetsFromTheGivenPoseOrWhereItWas) {
  // Tracking from the first frame, within 1 % of the distance flown (2 cm at
  // the start: the ground plane the rangefinder gives is exact here).
  for (int i = 0; i < 12; ++i) {
    const msg::VoEstimate estimate = fly(i);
    EXPECT_EQ(estimate.status, msg::VoStatus::TRACKING) << "frame " << i;
    EXPECT_LT((estimate.p_ned_m - truthAt(i).translation()).norm(), 0.02 + 0.01 * kStepM * i)
        << "frame " << i;
  }

  // A RESET for another node: tracking goes on, nothing counted.
  command("ppa", std::nullopt);
  for (int i = 12; i < 20; ++i) {
    const msg::VoEstimate estimate = fly(i);
    EXPECT_EQ(estimate.status, msg::VoStatus::TRACKING) << "frame " << i;
    EXPECT_EQ(estimate.num_resets, 0) << "frame " << i;
  }
  EXPECT_EQ(node_->commands().resetsReceived(), 0u);

  // A RESET for every node without a pose: the new map starts where the
  // motion model puts the frame, so the estimate goes on without a jump
  // (within the VO's 1 % of the distance).
  command("", std::nullopt);
  const msg::VoEstimate kept = fly(20);
  EXPECT_EQ(kept.num_resets, 1);
  EXPECT_LT((kept.p_ned_m - truthAt(20).translation()).norm(), 0.02 + 0.01 * kStepM * 20);
  for (int i = 21; i < 26; ++i) {
    const msg::VoEstimate estimate = fly(i);
    EXPECT_EQ(estimate.status, msg::VoStatus::TRACKING) << "frame " << i;
    EXPECT_EQ(estimate.num_resets, 1) << "frame " << i;
  }

  // A RESET for vo_direct to a pose 1 km off the truth, turned 90 deg: the
  // next estimate is that pose and the following ones carry on from it with
  // the truth's motion (within 1 % of the distance since and 0.1 deg).
  constexpr int kReset = 26;
  const Eigen::Isometry3d far = test::bodyPose(
      truthAt(kReset).translation() + Eigen::Vector3d(600.0, -800.0, -30.0), 0.0, 0.0, 90.0 * kDeg);
  command("vo_direct", far);
  const msg::VoEstimate restarted = fly(kReset);
  EXPECT_EQ(restarted.num_resets, 2);
  EXPECT_LT((restarted.p_ned_m - far.translation()).norm(), 1e-9);
  EXPECT_LT(angleDeg(poseOf(restarted).linear(), far.linear()), 1e-6);
  double worst_m = 0.0;
  for (int i = kReset + 1; i < 40; ++i) {
    const msg::VoEstimate estimate = fly(i);
    EXPECT_EQ(estimate.status, msg::VoStatus::TRACKING) << "frame " << i;
    EXPECT_EQ(estimate.num_resets, 2) << "frame " << i;
    const Eigen::Isometry3d expected = far * truthAt(kReset).inverse() * truthAt(i);
    const double error_m = (estimate.p_ned_m - expected.translation()).norm();
    worst_m = std::max(worst_m, error_m);
    EXPECT_LT(error_m, 0.02 + 0.01 * kStepM * (i - kReset)) << "frame " << i;
    EXPECT_LT(angleDeg(poseOf(estimate).linear(), expected.linear()), 0.1) << "frame " << i;
  }
  std::printf("vo_direct after a reset to a pose: at most %.3f m off\n", worst_m);
  EXPECT_EQ(node_->commands().resetsReceived(), 2u);
  EXPECT_EQ(node_->commands().droppedCommands(), 0u);
  // The debug image every 10 frames, an RGB image of the camera's size.
  ASSERT_EQ(debug_.size(), 4u);
  EXPECT_EQ(debug_.front().pixels.cols, kWidth);
  EXPECT_EQ(debug_.front().pixels.channels(), 3);
}

}  // namespace
}  // namespace nadir::vo
