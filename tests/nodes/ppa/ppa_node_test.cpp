// The PPA node on an in-process bus, fed 256x256 views of a texture sliding
// one pixel a frame (bench/ppa_scenes.h) at a rangefinder height of 100 m:
// RESETs on VO_COMMAND restart its position from the pose they carry, or
// without one where it was, and count in num_resets; a RESET addressed to
// another node changes nothing.
#include "nodes/ppa/ppa_node.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include "bench/ppa_scenes.h"
#include "core/bus.h"
#include "lcmtypes/bus_io.h"

namespace nadir::ppa {
namespace {

constexpr double kHeightM = 100.0;
constexpr double kOrigin = 384.0;  // the first frame's window in the 1024 px texture
constexpr std::int64_t kFrameUs = 5000;
// The default lens: 256 px over 50 deg, f = 128 / tan(25 deg) px; level flight
// at 100 m makes one pixel 100 / f = 0.3643 m on the ground.
const double kMetresPerPx = kHeightM * std::tan(25.0 * std::numbers::pi / 180.0) / 128.0;
// The chip aligns to within half a pixel (its translation step, as the
// visual odometry's tests hold it), once per key-frame the estimate chains.
constexpr double kAlignmentPx = 0.5;

const Eigen::Vector3d kStart(10.0, 20.0, -kHeightM);

class PpaNodeTest : public ::testing::Test {
 protected:
  PpaNodeTest() {
    params_.target_extraction = false;
    node_ = std::make_unique<PpaNode>(*bus_, params_, std::vector<Eigen::Vector2d>{});
    subscriptions_.push_back(msg::subscribe<msg::VoEstimate>(
        *bus_, params_.pose_channel,
        [this](const msg::VoEstimate& estimate) { estimates_.push_back(estimate); }));
    subscriptions_.push_back(msg::subscribe<msg::PpaOdometry>(
        *bus_, params_.odometry_channel,
        [this](const msg::PpaOdometry& odometry) { keyframes_ += odometry.new_keyframe ? 1 : 0; }));
    msg::Pose start;
    start.p_ned_m = kStart;
    msg::publish(*bus_, params_.truth_channel, start);
    bus_->handleAvailable();
  }

  // Frame i: the view slid i px to the right of the first (the vehicle i px east).
  msg::VoEstimate fly(int i) {
    const std::int64_t utime = i * kFrameUs;
    msg::Range range;
    range.utime = utime;
    range.range_m = kHeightM;
    range.status = msg::RangeStatus::VALID;
    range.max_range_m = 1000.0;
    msg::publish(*bus_, params_.range_channel, range);
    msg::publish(
        *bus_, params_.image_channel,
        msg::Image{utime, test::viewOf(texture_, kOrigin, kOrigin, i, 0.0, 0.0, 1.0), 0, {}});
    const std::size_t before = estimates_.size();
    bus_->handleAvailable();
    EXPECT_EQ(estimates_.size(), before + 1) << "frame " << i;
    return estimates_.back();
  }

  void command(const std::string& target, const std::optional<Eigen::Vector3d>& p_ned_m) {
    msg::VoCommand reset;
    reset.target = target;
    if (p_ned_m) {
      msg::Pose pose;
      pose.p_ned_m = *p_ned_m;
      // A yaw the PPA does not take: its attitude is the flight controller's.
      pose.q_world_body = Eigen::Quaterniond(Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitZ()));
      reset.initial_pose = pose;
    }
    msg::publish(*bus_, params_.command_channel, reset);
  }

  // Where the estimate should be at frame i when it was at p_ned_m at frame k,
  // and how far off it may be with the key-frames chained since.
  static Eigen::Vector3d movedEast(const Eigen::Vector3d& p_ned_m, int k, int i) {
    return p_ned_m + Eigen::Vector3d(0.0, (i - k) * kMetresPerPx, 0.0);
  }
  double tolerance_m(int keyframes_since) const {
    return kAlignmentPx * (1 + keyframes_since) * kMetresPerPx;
  }

  std::unique_ptr<core::Bus> bus_ = core::openBus("memq://");
  PpaNodeParams params_;
  std::unique_ptr<PpaNode> node_;
  std::vector<core::Subscription> subscriptions_;
  std::vector<msg::VoEstimate> estimates_;
  int keyframes_ = 0;
  cv::Mat texture_ = test::patchTexture(1024, 7);
};

TEST_F(PpaNodeTest, ResetRestartsFromTheGivenPositionOrWhereItWas) {
  // From the truth's start, one pixel east a frame; a RESET for another node
  // at frame 5 changes nothing.
  for (int i = 0; i < 10; ++i) {
    if (i == 5) command("vo_feature", Eigen::Vector3d(0.0, 0.0, 0.0));
    const msg::VoEstimate estimate = fly(i);
    EXPECT_EQ(estimate.status, msg::VoStatus::TRACKING) << "frame " << i;
    EXPECT_EQ(estimate.num_resets, 0) << "frame " << i;
    EXPECT_LT((estimate.p_ned_m - movedEast(kStart, 0, i)).norm(), tolerance_m(keyframes_ - 1))
        << "frame " << i;
  }
  EXPECT_EQ(node_->commands().resetsReceived(), 0u);

  // A RESET for every node without a pose: the position restarts where it was.
  const Eigen::Vector3d before = estimates_.back().p_ned_m;
  command("", std::nullopt);
  const msg::VoEstimate kept = fly(10);
  EXPECT_EQ(kept.num_resets, 1);
  EXPECT_LT((kept.p_ned_m - before).norm(), 1e-9);
  for (int i = 11; i < 16; ++i) EXPECT_EQ(fly(i).num_resets, 1) << "frame " << i;

  // A RESET for the PPA to a position 1 km off: the next estimate is there, the
  // attitude still the flight controller's (level, here), and the following
  // ones move east from it as the view slides.
  constexpr int kReset = 16;
  const Eigen::Vector3d far = kStart + Eigen::Vector3d(600.0, -800.0, 40.0);
  command("ppa", far);
  const msg::VoEstimate restarted = fly(kReset);
  EXPECT_EQ(restarted.status, msg::VoStatus::TRACKING);
  EXPECT_EQ(restarted.num_resets, 2);
  EXPECT_LT((restarted.p_ned_m - far).norm(), 1e-9);
  EXPECT_LT(restarted.q_world_body.angularDistance(Eigen::Quaterniond::Identity()), 1e-9);
  const int keyframes_at_reset = keyframes_;
  for (int i = kReset + 1; i < 30; ++i) {
    const msg::VoEstimate estimate = fly(i);
    EXPECT_EQ(estimate.num_resets, 2) << "frame " << i;
    EXPECT_LT((estimate.p_ned_m - movedEast(far, kReset, i)).norm(),
              tolerance_m(keyframes_ - keyframes_at_reset))
        << "frame " << i;
  }
  EXPECT_EQ(node_->commands().resetsReceived(), 2u);
  EXPECT_EQ(node_->commands().droppedCommands(), 0u);
}

}  // namespace
}  // namespace nadir::ppa
