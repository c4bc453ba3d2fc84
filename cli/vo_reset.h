#pragma once
// nadir vo reset: one vo_command_t RESET to a VO node (or every one), from the
// truth's next pose, from a pose given in NED metres and Z-Y-X degrees, or
// from what each node estimates now. The options, their checks and the
// command they make are here, apart from the verb, so that tests reach them.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/bus.h"
#include "lcmtypes/messages.h"

namespace CLI {
class App;
}

namespace nadir::cli {

struct VoResetOptions {
  std::string source;  // a VO node's name; empty: every VO node
  bool to_truth = false;
  // N E D (m), yaw pitch roll (deg, Z-Y-X, body FRD); empty: no pose.
  std::vector<double> pose;
  std::string channel = "VO_COMMAND";
  std::string truth_channel = "POSE_TRUTH";
  std::string url;  // empty: $LCM_DEFAULT_URL, else LCM's
  double truth_timeout_s = 5.0;
};

// Adds the options of `nadir vo reset` to its subcommand.
void addVoResetOptions(CLI::App& command, VoResetOptions& options);

// The names a reset may be addressed to: the registry's processing nodes and vo_direct.
std::vector<std::string> resettableSources();

// Throws std::invalid_argument naming what is wrong: a source not in `sources`,
// --to-truth with --pose, a --pose that is not six finite numbers.
void checkVoResetOptions(const VoResetOptions& options, const std::vector<std::string>& sources);

// The pose --pose gives (six numbers: N E D in m, yaw pitch roll in deg).
msg::Pose poseFromArguments(const std::vector<double>& pose, std::int64_t utime);

// The command the options make; `truth` is the pose --to-truth waited for.
// Its utime is the truth's, else `now_utime`.
msg::VoCommand makeResetCommand(const VoResetOptions& options, std::int64_t now_utime,
                                const std::optional<msg::Pose>& truth);

// The next pose_t on channel; throws std::runtime_error naming the channel if
// none comes within timeout (or the bus, a log, ends).
msg::Pose waitForPose(core::Bus& bus, const std::string& channel,
                      std::chrono::milliseconds timeout);

// What was sent, in one line: to whom, on which channel, and from which pose.
std::string describeCommand(const msg::VoCommand& command, const std::string& channel);

// Checks the options, waits for the truth if asked, publishes the command on
// bus and returns it.
msg::VoCommand sendVoReset(core::Bus& bus, const VoResetOptions& options);

}  // namespace nadir::cli
