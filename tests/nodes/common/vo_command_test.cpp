// VoCommandListener on an in-process bus: which RESETs reach a node (its name,
// or an empty target for every node), the pose a RESET carries, and malformed
// commands dropped and counted with their reason.
#include "nodes/common/vo_command.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "core/bus.h"
#include "lcmtypes/bus_io.h"
#include "nadir/vo_command_t.hpp"
#include "tests/support/lcm_messages.h"

namespace nadir::nodes {
namespace {

constexpr char kChannel[] = "VO_COMMAND";

class VoCommandListenerTest : public ::testing::Test {
 protected:
  void send(const msg::VoCommand& command) {
    msg::publish(*bus_, kChannel, command);
    bus_->handleAvailable();
  }

  static msg::VoCommand reset(std::int64_t utime, const std::string& target) {
    msg::VoCommand command;
    command.utime = utime;
    command.target = target;
    return command;
  }

  std::unique_ptr<core::Bus> bus_ = core::openBus("memq://");
  std::vector<VoResetRequest> received_;
  VoCommandListener listener_{*bus_, kChannel, "vo_feature", [this](const VoResetRequest& request) {
                                received_.push_back(request);
                              }};
};

// A RESET to the node's name or to every node arrives; one to another node does not.
TEST_F(VoCommandListenerTest, TakesResetsForItsNameOrForEveryNode) {
  send(reset(1, "vo_feature"));
  send(reset(2, "ppa"));
  send(reset(3, ""));
  send(reset(4, "vo_direct"));
  send(reset(5, "vo_feature_2"));  // a name that only starts like it
  ASSERT_EQ(received_.size(), 2u);
  EXPECT_EQ(received_[0].utime, 1);
  EXPECT_EQ(received_[1].utime, 3);
  EXPECT_FALSE(received_[0].T_world_body.has_value());
  EXPECT_EQ(listener_.resetsReceived(), 2u);
  EXPECT_EQ(listener_.droppedCommands(), 0u);
  EXPECT_TRUE(listener_.firstDropReason().empty());
}

// The initial pose becomes T_world_body: a yaw of 90 deg at (100, -200, -50) m
// maps the body's x axis to the world's east.
TEST_F(VoCommandListenerTest, InitialPoseBecomesTWorldBody) {
  msg::VoCommand command = reset(7, "");
  msg::Pose pose;
  pose.utime = 7;
  pose.p_ned_m = Eigen::Vector3d(100.0, -200.0, -50.0);
  pose.q_world_body = Eigen::Quaterniond(std::sqrt(0.5), 0.0, 0.0, std::sqrt(0.5));
  command.initial_pose = pose;
  send(command);
  ASSERT_EQ(received_.size(), 1u);
  ASSERT_TRUE(received_[0].T_world_body.has_value());
  const Eigen::Isometry3d& T = *received_[0].T_world_body;
  EXPECT_NEAR((T.translation() - Eigen::Vector3d(100.0, -200.0, -50.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((T.linear() * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 0.0,
              1e-12);
  EXPECT_NEAR((T.linear() * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitZ()).norm(), 0.0,
              1e-12);
}

// A command the type does not define, a pose that is not a rotation and bytes of
// another type are dropped and counted, the first one's reason kept; the bytes
// of another type count in the bus's decode errors too.
TEST_F(VoCommandListenerTest, MalformedCommandsAreDroppedAndCounted) {
  nadir::vo_command_t unknown{};
  unknown.utime = 11;
  unknown.target = "vo_feature";
  unknown.command = 5;
  test::publish(*bus_, kChannel, unknown);

  nadir::vo_command_t bad_pose{};
  bad_pose.utime = 12;
  bad_pose.command = nadir::vo_command_t::COMMAND_RESET;
  bad_pose.has_initial_pose = true;
  bad_pose.initial_pose.utime = 12;
  bad_pose.initial_pose.orientation[0] = 2.0;  // norm 2: not a rotation
  test::publish(*bus_, kChannel, bad_pose);

  msg::Pose pose;
  pose.utime = 13;
  msg::publish(*bus_, kChannel, pose);
  bus_->handleAvailable();

  EXPECT_TRUE(received_.empty());
  EXPECT_EQ(listener_.resetsReceived(), 0u);
  EXPECT_EQ(listener_.droppedCommands(), 3u);
  EXPECT_NE(listener_.firstDropReason().find("vo_command_t at utime 11"), std::string::npos)
      << listener_.firstDropReason();
  EXPECT_NE(listener_.firstDropReason().find("command 5 is not defined"), std::string::npos)
      << listener_.firstDropReason();
  EXPECT_EQ(bus_->stats().at(kChannel).decode_errors, 1u);

  // A good command after them still arrives.
  send(reset(14, "vo_feature"));
  ASSERT_EQ(received_.size(), 1u);
  EXPECT_EQ(received_[0].utime, 14);
}

// The request a command makes, without a bus: nothing for another node.
TEST(ResetRequestFor, FiltersByTarget) {
  msg::VoCommand command;
  command.utime = 3;
  command.target = "ppa";
  EXPECT_FALSE(resetRequestFor(command, "vo_feature").has_value());
  ASSERT_TRUE(resetRequestFor(command, "ppa").has_value());
  EXPECT_EQ(resetRequestFor(command, "ppa")->utime, 3);
  command.target.clear();
  EXPECT_TRUE(resetRequestFor(command, "vo_direct").has_value());
}

// A listener needs the name it answers to.
TEST(VoCommandListener, EmptySourceIsRefused) {
  const std::unique_ptr<core::Bus> bus = core::openBus("memq://");
  EXPECT_THROW(VoCommandListener(*bus, kChannel, "", [](const VoResetRequest&) {}),
               std::invalid_argument);
}

}  // namespace
}  // namespace nadir::nodes
