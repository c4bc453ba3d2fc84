#pragma once
// nadir-control's work on a bus, the same in the live node and in `nadir run`:
// each gate_pattern_t from the PPA goes through the gate controller
// (gate_controller.h) with the PPA camera's lens (camera_info_t), and the
// steering and speed go out as drive_command_t, stamped with the time they
// take effect: the frame's time plus the pipeline's latency (the chip's time
// for the frame, the transfer of the coordinates and the controller's own
// time, as Liu et al. (2021) table 2 counts them). Bad messages are dropped
// and counted.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/bus.h"
#include "core/params.h"
#include "lcmtypes/messages.h"
#include "nodes/control/gate_controller.h"

namespace nadir::control {

// The node's name: its scenario group and program.
inline constexpr char kControlName[] = "control";

struct ControlNodeParams {
  // In a scenario: run the controller (nadir run composes it, nadir launch starts nadir-control).
  bool enabled = false;
  std::string pattern_channel = "PPA_PATTERN";
  std::string info_channel = "CAMERA_PPA_INFO";
  std::string command_channel = "DRIVE_COMMAND";
  // The coordinates' transfer from the chip to the controller's computer and
  // the controller's own time, s (Liu et al. (2021) table 2: about 24 and 1 us).
  double transfer_s = 24e-6;
  double compute_s = 1e-6;
  GateControllerParams controller;

  void visit(core::ParamVisitor& v);
};

struct ControlCounts {
  std::int64_t patterns = 0;
  std::int64_t commands = 0;
  std::int64_t without_lens = 0;  // patterns before any camera_info_t: stop commanded
  std::int64_t dropped = 0;
};

class ControlNode {
 public:
  ControlNode(core::Bus& bus, const ControlNodeParams& params);

  const ControlCounts& counts() const { return counts_; }
  const std::string& firstDropReason() const { return first_drop_reason_; }
  // Commands by mode (DriveCommand::Mode order).
  const std::vector<std::int64_t>& modes() const { return modes_; }

 private:
  void onPattern(const msg::GatePattern& pattern);
  void drop(const std::string& reason);

  core::Bus& bus_;
  ControlNodeParams params_;
  GateController controller_;
  std::optional<Lens> lens_;
  ControlCounts counts_;
  std::vector<std::int64_t> modes_ = std::vector<std::int64_t>(5, 0);
  std::string first_drop_reason_;
  std::vector<core::Subscription> subscriptions_;
};

}  // namespace nadir::control
