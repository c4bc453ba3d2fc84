#pragma once
// The viewer's way to the VO nodes: vo_command_t RESETs published on a bus.

#include <cstdint>
#include <optional>
#include <string>

#include "core/bus.h"
#include "lcmtypes/messages.h"

namespace nadir::gui {

class VoResetSender {
 public:
  // Publishes on bus, which must outlive the sender.
  explicit VoResetSender(core::Bus& bus, std::string channel = "VO_COMMAND");

  // A RESET to `source` (empty: every VO node), from `pose` when given (else
  // each node restarts from what it estimates now); stamped with the pose's
  // utime, else now_utime. Returns what was sent.
  msg::VoCommand send(const std::string& source, const std::optional<msg::Pose>& pose,
                      std::int64_t now_utime);
  const std::string& channel() const { return channel_; }

 private:
  core::Bus& bus_;
  std::string channel_;
};

}  // namespace nadir::gui
