#include "cli/vo_reset.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

#include "core/clock.h"
#include "core/frames.h"
#include "lcmtypes/bus_io.h"
#include "nodes/registry.h"

namespace nadir::cli {
namespace {

constexpr double kRadPerDeg = std::numbers::pi / 180.0;
constexpr char kPoseOption[] = "--pose";
constexpr char kToTruthOption[] = "--to-truth";

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& name : names) out += (out.empty() ? "" : ", ") + name;
  return out;
}

// Degrees for printing, without a negative zero.
double degrees(double rad) { return rad / kRadPerDeg + 0.0; }

}  // namespace

void addVoResetOptions(CLI::App& command, VoResetOptions& options) {
  command.add_option("--source", options.source,
                     "the VO node to reset (ppa, vo_feature, vo_direct); default: every one");
  auto* to_truth =
      command.add_flag(kToTruthOption, options.to_truth,
                       "restart from the truth's next pose (waits for it on --truth-channel)");
  command
      .add_option(kPoseOption, options.pose,
                  "restart from this pose: N E D (m) YAW PITCH ROLL (deg, Z-Y-X, body FRD)")
      ->expected(6)
      ->excludes(to_truth);
  command.add_option("--channel", options.channel, "vo_command_t channel")->capture_default_str();
  command.add_option("--truth-channel", options.truth_channel, "pose_t truth for --to-truth")
      ->capture_default_str();
  command
      .add_option("--timeout", options.truth_timeout_s,
                  "seconds to wait for the truth with --to-truth")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  command.add_option("--url", options.url,
                     "bus to publish on (udpm://, file://PATH?mode=w); default $LCM_DEFAULT_URL "
                     "or LCM's");
}

std::vector<std::string> resettableSources() {
  std::vector<std::string> sources;
  for (const auto& entry : nodes::registry()) {
    if (entry->info().role == nodes::EntryInfo::Role::kProcessing) {
      sources.push_back(entry->info().name);
    }
  }
  // The direct VO answers to its name whether or not this build has it.
  if (std::find(sources.begin(), sources.end(), "vo_direct") == sources.end()) {
    sources.emplace_back("vo_direct");
  }
  return sources;
}

void checkVoResetOptions(const VoResetOptions& options, const std::vector<std::string>& sources) {
  if (!options.source.empty() &&
      std::find(sources.begin(), sources.end(), options.source) == sources.end()) {
    throw std::invalid_argument("--source " + options.source + ": no such VO node (the VO nodes: " +
                                joined(sources) + "; leave --source out for every one)");
  }
  if (options.to_truth && !options.pose.empty()) {
    throw std::invalid_argument(std::string(kToTruthOption) + " and " + kPoseOption +
                                " both give the pose: give one");
  }
  if (!options.pose.empty() && options.pose.size() != 6) {
    throw std::invalid_argument(std::string(kPoseOption) + " takes 6 numbers (N E D YAW PITCH " +
                                "ROLL), not " + std::to_string(options.pose.size()));
  }
  for (const double value : options.pose) {
    if (!std::isfinite(value)) {
      throw std::invalid_argument(std::string(kPoseOption) + ": " + std::to_string(value) +
                                  " is not a finite number");
    }
  }
  if (!(options.truth_timeout_s > 0.0)) {
    throw std::invalid_argument("--timeout must be more than 0 s");
  }
}

msg::Pose poseFromArguments(const std::vector<double>& pose, std::int64_t utime) {
  if (pose.size() != 6) throw std::invalid_argument("a pose is 6 numbers: N E D YAW PITCH ROLL");
  msg::Pose out;
  out.utime = utime;
  out.p_ned_m = Eigen::Vector3d(pose[0], pose[1], pose[2]);
  out.q_world_body = core::quaternionFromRpy({.roll_rad = pose[5] * kRadPerDeg,
                                              .pitch_rad = pose[4] * kRadPerDeg,
                                              .yaw_rad = pose[3] * kRadPerDeg});
  return out;
}

msg::VoCommand makeResetCommand(const VoResetOptions& options, std::int64_t now_utime,
                                const std::optional<msg::Pose>& truth) {
  msg::VoCommand command;
  command.utime = truth ? truth->utime : now_utime;
  command.target = options.source;
  command.command = msg::VoCommand::Kind::RESET;
  if (options.to_truth) {
    if (!truth) throw std::logic_error("makeResetCommand: --to-truth without the truth's pose");
    command.initial_pose = *truth;
  } else if (!options.pose.empty()) {
    command.initial_pose = poseFromArguments(options.pose, command.utime);
  }
  return command;
}

msg::Pose waitForPose(core::Bus& bus, const std::string& channel,
                      std::chrono::milliseconds timeout) {
  std::optional<msg::Pose> pose;
  const core::Subscription subscription =
      msg::subscribe<msg::Pose>(bus, channel, [&pose](const msg::Pose& message) {
        if (!pose) pose = message;
      });
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!pose) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    // handle() is false once its wait ran out (or a log ended) with nothing.
    if (left.count() <= 0 || !bus.handle(left)) break;
  }
  if (!pose) {
    char seconds[32];
    std::snprintf(seconds, sizeof(seconds), "%g", static_cast<double>(timeout.count()) / 1000.0);
    throw std::runtime_error("no pose_t came on " + channel + " within " + seconds + " s on " +
                             bus.url() + " (is the simulator running? --truth-channel names " +
                             "another channel)");
  }
  return *pose;
}

std::string describeCommand(const msg::VoCommand& command, const std::string& channel) {
  std::string text =
      "RESET to " + (command.target.empty() ? std::string("every VO node") : command.target);
  text += " on " + channel;
  if (!command.initial_pose) {
    return text + ", from the pose each estimates now";
  }
  const msg::Pose& pose = *command.initial_pose;
  const core::RollPitchYaw rpy = core::rpyFromQuaternion(pose.q_world_body);
  char where[200];
  std::snprintf(where, sizeof(where),
                ", from N %.2f E %.2f D %.2f m, yaw %.2f pitch %.2f roll %.2f deg (utime %lld)",
                pose.p_ned_m.x(), pose.p_ned_m.y(), pose.p_ned_m.z(), degrees(rpy.yaw_rad),
                degrees(rpy.pitch_rad), degrees(rpy.roll_rad), static_cast<long long>(pose.utime));
  return text + where;
}

msg::VoCommand sendVoReset(core::Bus& bus, const VoResetOptions& options) {
  checkVoResetOptions(options, resettableSources());
  std::optional<msg::Pose> truth;
  if (options.to_truth) {
    truth = waitForPose(bus, options.truth_channel,
                        std::chrono::milliseconds(std::llround(options.truth_timeout_s * 1000.0)));
  }
  const msg::VoCommand command = makeResetCommand(options, core::wallClockUtime(), truth);
  msg::publish(bus, options.channel, command);
  return command;
}

}  // namespace nadir::cli
