// nadir vo reset: its options as parsed, their checks, the command they make
// (the pose from N E D and Z-Y-X degrees), waiting for the truth, and the verb
// itself writing its command into a log.
#include "cli/vo_reset.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "core/bus.h"
#include "core/lcm_log.h"
#include "lcmtypes/bus_io.h"
#include "tests/support/run_command.h"

namespace nadir::cli {
namespace {

// Parses `vo reset`'s options from a command line.
VoResetOptions parse(const std::string& line) {
  CLI::App app;
  VoResetOptions options;
  addVoResetOptions(app, options);
  app.parse(line);
  return options;
}

std::string errorOf(const VoResetOptions& options) {
  try {
    checkVoResetOptions(options, resettableSources());
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return {};
}

std::pair<int, std::string> run(const std::string& command) {
  return nadir::test::runCommand(command);
}

// The VO nodes of the registry answer to their names, and the direct VO to its;
// the simulator and the camera are no VO nodes.
TEST(VoReset, SourcesAreTheVoNodes) {
  const std::vector<std::string> sources = resettableSources();
  for (const char* name : {"ppa", "vo_feature", "vo_direct"}) {
    EXPECT_EQ(std::count(sources.begin(), sources.end(), name), 1) << name;
  }
  for (const char* name : {"sim", "camera"}) {
    EXPECT_EQ(std::count(sources.begin(), sources.end(), name), 0) << name;
  }
}

TEST(VoReset, ParsesItsOptions) {
  const VoResetOptions none = parse("");
  EXPECT_TRUE(none.source.empty());
  EXPECT_FALSE(none.to_truth);
  EXPECT_TRUE(none.pose.empty());
  EXPECT_EQ(none.channel, "VO_COMMAND");
  EXPECT_EQ(none.truth_channel, "POSE_TRUTH");
  EXPECT_EQ(errorOf(none), "");

  const VoResetOptions pose = parse("--source ppa --pose 1 -2 -30.5 90 0 -5 --channel CMD");
  EXPECT_EQ(pose.source, "ppa");
  EXPECT_EQ(pose.pose, (std::vector<double>{1, -2, -30.5, 90, 0, -5}));
  EXPECT_EQ(pose.channel, "CMD");
  EXPECT_EQ(errorOf(pose), "");

  const VoResetOptions truth = parse("--to-truth --truth-channel TRUTH --timeout 2");
  EXPECT_TRUE(truth.to_truth);
  EXPECT_EQ(truth.truth_channel, "TRUTH");
  EXPECT_EQ(truth.truth_timeout_s, 2.0);
}

// Wrong input is refused, naming what is wrong.
TEST(VoReset, RefusesWrongInput) {
  EXPECT_THROW(parse("--to-truth --pose 0 0 0 0 0 0"), CLI::ExcludesError);
  EXPECT_THROW(parse("--pose 1 2 3"), CLI::ParseError);
  EXPECT_THROW(parse("--timeout 0"), CLI::ValidationError);

  VoResetOptions options;
  options.source = "vo_fetaure";
  EXPECT_EQ(
      errorOf(options), "--source vo_fetaure: no such VO node (the VO nodes: " + [] {
        std::string names;
        for (const std::string& name : resettableSources()) {
          names += (names.empty() ? "" : ", ") + name;
        }
        return names;
      }() + "; leave --source out for every one)");
  options.source = "camera";
  EXPECT_NE(errorOf(options).find("--source camera: no such VO node"), std::string::npos);

  options = {};
  options.to_truth = true;
  options.pose = {0, 0, 0, 0, 0, 0};
  EXPECT_EQ(errorOf(options), "--to-truth and --pose both give the pose: give one");
  options.to_truth = false;
  options.pose = {0, 0, std::nan(""), 0, 0, 0};
  EXPECT_NE(errorOf(options).find("is not a finite number"), std::string::npos);
  options.pose = {0, 0, 0};
  EXPECT_EQ(errorOf(options), "--pose takes 6 numbers (N E D YAW PITCH ROLL), not 3");
}

// --pose: N E D in metres, then yaw, pitch and roll in degrees (Z-Y-X, body
// FRD), checked by where the body's axes go: yaw 90 points the nose east,
// pitch 30 raises it (up is -D), roll 90 puts the right wing down.
TEST(VoReset, PoseFromNedAndZyxDegrees) {
  const msg::Pose yawed = poseFromArguments({100, -20, -50, 90, 0, 0}, 42);
  EXPECT_EQ(yawed.utime, 42);
  EXPECT_EQ(yawed.p_ned_m, Eigen::Vector3d(100, -20, -50));
  const Eigen::Matrix3d R_yaw = yawed.q_world_body.toRotationMatrix();
  EXPECT_NEAR((R_yaw * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 0.0, 1e-12);

  const msg::Pose pitched = poseFromArguments({0, 0, 0, 0, 30, 0}, 0);
  const Eigen::Vector3d nose = pitched.q_world_body * Eigen::Vector3d::UnitX();
  EXPECT_NEAR((nose - Eigen::Vector3d(std::sqrt(3.0) / 2.0, 0.0, -0.5)).norm(), 0.0, 1e-12);

  // Yaw 90 then roll 90: the right wing (body y) points down.
  const msg::Pose rolled = poseFromArguments({0, 0, 0, 90, 0, 90}, 0);
  EXPECT_NEAR(((rolled.q_world_body * Eigen::Vector3d::UnitY()) - Eigen::Vector3d::UnitZ()).norm(),
              0.0, 1e-12);
  EXPECT_NEAR(((rolled.q_world_body * Eigen::Vector3d::UnitX()) - Eigen::Vector3d::UnitY()).norm(),
              0.0, 1e-12);
}

TEST(VoReset, CommandCarriesThePoseAsked) {
  VoResetOptions options;
  const msg::VoCommand plain = makeResetCommand(options, 1000, std::nullopt);
  EXPECT_EQ(plain.utime, 1000);
  EXPECT_TRUE(plain.target.empty());
  EXPECT_EQ(plain.command, msg::VoCommand::Kind::RESET);
  EXPECT_FALSE(plain.initial_pose.has_value());
  EXPECT_EQ(describeCommand(plain, "VO_COMMAND"),
            "RESET to every VO node on VO_COMMAND, from the pose each estimates now");

  options.source = "vo_feature";
  options.pose = {1, 2, -3, 0, 0, 0};
  const msg::VoCommand posed = makeResetCommand(options, 1000, std::nullopt);
  EXPECT_EQ(posed.target, "vo_feature");
  ASSERT_TRUE(posed.initial_pose.has_value());
  EXPECT_EQ(posed.initial_pose->p_ned_m, Eigen::Vector3d(1, 2, -3));
  EXPECT_EQ(describeCommand(posed, "VO_COMMAND"),
            "RESET to vo_feature on VO_COMMAND, from N 1.00 E 2.00 D -3.00 m, yaw 0.00 pitch "
            "0.00 roll 0.00 deg (utime 1000)");

  options = {};
  options.to_truth = true;
  msg::Pose truth;
  truth.utime = 5000000;
  truth.p_ned_m = Eigen::Vector3d(7, 8, -9);
  const msg::VoCommand to_truth = makeResetCommand(options, 1000, truth);
  EXPECT_EQ(to_truth.utime, 5000000);
  ASSERT_TRUE(to_truth.initial_pose.has_value());
  EXPECT_EQ(to_truth.initial_pose->p_ned_m, Eigen::Vector3d(7, 8, -9));
}

// --to-truth takes the first pose_t on the truth channel (not another
// channel's); with none, it says so, naming the channel and the wait.
TEST(VoReset, WaitsForTheTruth) {
  const std::string log = ::testing::TempDir() + "nadir_vo_reset_truth.lcmlog";
  std::filesystem::remove(log);
  {
    const std::unique_ptr<core::Bus> writer = core::openBus("file://" + log + "?mode=w");
    msg::Pose other;
    other.utime = 1;
    msg::publish(*writer, "POSE_OTHER", other);
    msg::Pose truth;
    truth.utime = 2;
    truth.p_ned_m = Eigen::Vector3d(3, 4, -5);
    msg::publish(*writer, "POSE_TRUTH", truth);
    truth.utime = 3;
    msg::publish(*writer, "POSE_TRUTH", truth);
  }
  const std::unique_ptr<core::Bus> reader = core::openBus("file://" + log + "?mode=r");
  const msg::Pose got = waitForPose(*reader, "POSE_TRUTH", std::chrono::milliseconds(5000));
  EXPECT_EQ(got.utime, 2);
  EXPECT_EQ(got.p_ned_m, Eigen::Vector3d(3, 4, -5));

  const std::unique_ptr<core::Bus> empty = core::openBus("memq://");
  try {
    waitForPose(*empty, "POSE_TRUTH", std::chrono::milliseconds(50));
    ADD_FAILURE() << "no error without a truth";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("no pose_t came on POSE_TRUTH within 0.05 s"),
              std::string::npos)
        << error.what();
  }
}

// The verb writes one vo_command_t into a log bus and says what it sent; a
// wrong name stops it before anything is sent.
TEST(VoReset, VerbSendsOneCommand) {
  const std::string log = ::testing::TempDir() + "nadir_vo_reset_verb.lcmlog";
  std::filesystem::remove(log);
  const auto [status, output] =
      run(std::string(NADIR_BIN) + " vo reset --source vo_feature --pose 10 20 -100 45 0 0 " +
          "--url 'file://" + log + "?mode=w'");
  ASSERT_EQ(status, 0) << output;
  EXPECT_NE(output.find("nadir vo reset: sent RESET to vo_feature on VO_COMMAND, from N 10.00 E "
                        "20.00 D -100.00 m, yaw 45.00"),
            std::string::npos)
      << output;
  core::LcmLogReader reader(log);
  std::vector<msg::VoCommand> commands;
  while (const std::optional<core::LogEvent> event = reader.next()) {
    ASSERT_EQ(event->channel, "VO_COMMAND");
    commands.push_back(msg::decode<msg::VoCommand>(event->data));
  }
  ASSERT_EQ(commands.size(), 1u);
  EXPECT_EQ(commands[0].target, "vo_feature");
  ASSERT_TRUE(commands[0].initial_pose.has_value());
  EXPECT_EQ(commands[0].initial_pose->p_ned_m, Eigen::Vector3d(10, 20, -100));
  const Eigen::Vector3d nose = commands[0].initial_pose->q_world_body * Eigen::Vector3d::UnitX();
  EXPECT_NEAR((nose - Eigen::Vector3d(std::sqrt(0.5), std::sqrt(0.5), 0.0)).norm(), 0.0, 1e-12);

  const std::string untouched = ::testing::TempDir() + "nadir_vo_reset_none.lcmlog";
  std::filesystem::remove(untouched);
  const auto [bad_status, bad_output] = run(
      std::string(NADIR_BIN) + " vo reset --source nope --url 'file://" + untouched + "?mode=w'");
  EXPECT_EQ(bad_status, 1);
  EXPECT_NE(bad_output.find("nadir: error: --source nope: no such VO node"), std::string::npos)
      << bad_output;
  EXPECT_FALSE(std::filesystem::exists(untouched));
}

}  // namespace
}  // namespace nadir::cli
