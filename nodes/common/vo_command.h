#pragma once
// What a VO node takes from vo_command_t: the RESET commands addressed to it
// (its source name) or to every VO node, as plain requests.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "core/bus.h"
#include "lcmtypes/messages.h"

namespace nadir::nodes {

// A reset request for one VO node: restart the estimate (drop the map/state).
struct VoResetRequest {
  std::int64_t utime = 0;
  // Restart from this T_world_body (local NED, body FRD); none: restart from the
  // pose the node estimates now (the map is dropped, the estimate does not jump).
  std::optional<Eigen::Isometry3d> T_world_body;
};

// The request a command makes; nothing if it is not a RESET for `source`
// (target == source, or an empty target: every node).
std::optional<VoResetRequest> resetRequestFor(const msg::VoCommand& command,
                                              const std::string& source);

class VoCommandListener {
 public:
  // Calls on_reset (on the bus's dispatch thread, like every handler) for each
  // RESET addressed to `source` or to every node. Malformed commands are counted and dropped.
  VoCommandListener(core::Bus& bus, const std::string& channel, const std::string& source,
                    std::function<void(const VoResetRequest&)> on_reset);
  VoCommandListener(const VoCommandListener&) = delete;
  VoCommandListener& operator=(const VoCommandListener&) = delete;

  std::uint64_t resetsReceived() const { return resets_received_; }
  std::uint64_t droppedCommands() const { return dropped_commands_; }
  // Why the first dropped command was dropped; empty if none was.
  const std::string& firstDropReason() const { return first_drop_reason_; }

 private:
  void take(core::Bus& bus, const core::RawMessage& message);
  void drop(const std::string& reason);

  std::string source_;
  std::function<void(const VoResetRequest&)> on_reset_;
  std::uint64_t resets_received_ = 0;
  std::uint64_t dropped_commands_ = 0;
  std::string first_drop_reason_;
  core::Subscription subscription_;
};

}  // namespace nadir::nodes
