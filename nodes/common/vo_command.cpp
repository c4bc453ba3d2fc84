#include "nodes/common/vo_command.h"

#include <stdexcept>
#include <utility>

#include "lcmtypes/codec.h"

namespace nadir::nodes {

std::optional<VoResetRequest> resetRequestFor(const msg::VoCommand& command,
                                              const std::string& source) {
  if (command.command != msg::VoCommand::Kind::RESET) return std::nullopt;
  if (!command.target.empty() && command.target != source) return std::nullopt;
  VoResetRequest request;
  request.utime = command.utime;
  if (command.initial_pose) {
    Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
    T_world_body.linear() = command.initial_pose->q_world_body.toRotationMatrix();
    T_world_body.translation() = command.initial_pose->p_ned_m;
    request.T_world_body = T_world_body;
  }
  return request;
}

VoCommandListener::VoCommandListener(core::Bus& bus, const std::string& channel,
                                     const std::string& source,
                                     std::function<void(const VoResetRequest&)> on_reset)
    : source_(source), on_reset_(std::move(on_reset)) {
  if (source_.empty()) throw std::invalid_argument("VoCommandListener: the source name is empty");
  // Not msg::subscribe: bytes of another type are this node's drops too.
  subscription_ =
      bus.subscribe(channel, [this, &bus](const core::RawMessage& message) { take(bus, message); });
}

void VoCommandListener::take(core::Bus& bus, const core::RawMessage& message) {
  msg::VoCommand command;
  try {
    command = msg::decode<msg::VoCommand>(message.data, message.size);
  } catch (const msg::DecodeError& error) {
    bus.countDecodeError(message.channel);
    drop(error.what());
    return;
  } catch (const msg::InvalidMessage& error) {
    drop(error.what());
    return;
  }
  const std::optional<VoResetRequest> request = resetRequestFor(command, source_);
  if (!request) return;
  ++resets_received_;
  on_reset_(*request);
}

void VoCommandListener::drop(const std::string& reason) {
  if (dropped_commands_++ == 0) first_drop_reason_ = reason;
}

}  // namespace nadir::nodes
