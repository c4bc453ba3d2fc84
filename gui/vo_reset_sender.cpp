#include "gui/vo_reset_sender.h"

#include <utility>

#include "lcmtypes/bus_io.h"

namespace nadir::gui {

VoResetSender::VoResetSender(core::Bus& bus, std::string channel)
    : bus_(bus), channel_(std::move(channel)) {}

msg::VoCommand VoResetSender::send(const std::string& source, const std::optional<msg::Pose>& pose,
                                   std::int64_t now_utime) {
  msg::VoCommand command;
  command.utime = pose ? pose->utime : now_utime;
  command.target = source;
  command.command = msg::VoCommand::Kind::RESET;
  command.initial_pose = pose;
  msg::publish(bus_, channel_, command);
  return command;
}

}  // namespace nadir::gui
