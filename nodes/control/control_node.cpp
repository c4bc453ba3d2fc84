#include "nodes/control/control_node.h"

#include "core/clock.h"
#include "lcmtypes/bus_io.h"

namespace nadir::control {

void ControlNodeParams::visit(core::ParamVisitor& v) {
  v.field("enabled", &enabled, {.doc = "run the rover's controller in this scenario"});
  v.field("pattern_channel", &pattern_channel, {.doc = "gate_pattern_t in: the PPA's patterns"});
  v.field("info_channel", &info_channel, {.doc = "camera_info_t in: the PPA camera's lens"});
  v.field("command_channel", &command_channel, {.doc = "drive_command_t out"});
  v.field("transfer_s", &transfer_s,
          {.doc = "the coordinates' transfer to the controller, s", .min = 0, .max = 10});
  v.field("compute_s", &compute_s, {.doc = "the controller's own time, s", .min = 0, .max = 10});
  controller.visit(v);
}

ControlNode::ControlNode(core::Bus& bus, const ControlNodeParams& params)
    : bus_(bus), params_(params), controller_(params.controller) {
  core::validateParams([this](core::ParamVisitor& v) { params_.visit(v); }, "control");
  subscriptions_.push_back(msg::subscribe<msg::CameraInfo>(
      bus_, params_.info_channel,
      [this](const msg::CameraInfo& info) {
        lens_ = Lens{info.fx, info.fy, info.cx, info.cy};
      },
      [this](const std::string& reason) { drop(reason); }));
  subscriptions_.push_back(msg::subscribe<msg::GatePattern>(
      bus_, params_.pattern_channel,
      [this](const msg::GatePattern& pattern) { onPattern(pattern); },
      [this](const std::string& reason) { drop(reason); }));
}

void ControlNode::drop(const std::string& reason) {
  if (counts_.dropped++ == 0) first_drop_reason_ = reason;
}

void ControlNode::onPattern(const msg::GatePattern& pattern) {
  ++counts_.patterns;
  SteeringCommand steering;
  if (lens_) {
    PatternObservation observation;
    observation.utime = pattern.utime;
    // msg::PatternKind lists the controller's patterns in their order.
    observation.kind = static_cast<Pattern>(static_cast<int>(pattern.kind));
    observation.disks_px = pattern.disks_px;
    steering = controller_.update(observation, *lens_);
  } else {
    ++counts_.without_lens;
  }
  msg::DriveCommand command;
  command.frame_utime = pattern.utime;
  command.utime = pattern.utime + core::utimeFromSeconds(pattern.chip_time_s + params_.transfer_s +
                                                         params_.compute_s);
  command.steer_rad = steering.steer_rad;
  command.speed_mps = steering.speed_mps;
  command.mode = static_cast<msg::DriveCommand::Mode>(static_cast<int>(steering.mode));
  command.lateral_error_rad = steering.lateral_error_rad;
  command.deformation = steering.deformation;
  ++modes_[static_cast<std::size_t>(command.mode)];
  ++counts_.commands;
  msg::publish(bus_, params_.command_channel, command);
}

}  // namespace nadir::control
