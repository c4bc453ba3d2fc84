#pragma once
// nadir-ppa's work on a bus, the same in the live node and in `nadir run`: the
// PPA camera's frames go through the emulated chip (visual odometry, then
// target extraction), the host turns the alignment into a position with the
// rangefinder and the flight controller's attitude, and the node publishes
// vo_estimate_t, ppa_odometry_t and target_detection_t; in mode gates the
// frames go through the gate tracker instead and it publishes gate_pattern_t.
// A RESET on
// VO_COMMAND drops the key-frame and restarts the position at the next frame.
// Bad messages are dropped and counted.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/bus.h"
#include "lcmtypes/image.h"
#include "lcmtypes/messages.h"
#include "nodes/common/flight_inputs.h"
#include "nodes/common/vo_command.h"
#include "nodes/ppa/gate_tracker.h"
#include "nodes/ppa/ppa_array.h"
#include "nodes/ppa/ppa_host.h"
#include "nodes/ppa/ppa_node_params.h"
#include "nodes/ppa/target_extraction.h"
#include "nodes/ppa/visual_odometry.h"

namespace nadir::ppa {

// The node's name: its scenario group, its source name in vo_estimate_t and the metrics.
inline constexpr char kSourceName[] = "ppa";

class PpaNode {
 public:
  // targets_ne_m: the known concentric targets (north, east) for position correction.
  PpaNode(core::Bus& bus, const PpaNodeParams& params, std::vector<Eigen::Vector2d> targets_ne_m);

  std::uint64_t frames() const { return frames_; }
  std::uint64_t droppedImages() const { return dropped_images_; }
  // The first dropped image's problem; empty if none.
  const std::string& firstDropReason() const { return first_drop_reason_; }
  // Mean emulated instructions per frame so far.
  double meanInstructionsPerFrame() const;
  // Resets applied (vo_estimate_t's num_resets).
  int resets() const { return resets_; }
  const nodes::VoCommandListener& commands() const { return commands_; }
  // num_resets starts here (a process restarted after one that died).
  void continueResetCount(int resets_before) { resets_ = resets_before; }

 private:
  void onImage(const msg::Image& image);
  // Mode gates: the frame through the gate tracker, its pattern published.
  void trackPattern(std::int64_t utime, const cv::Mat& gray);
  void applyResets();
  void drop(const std::string& reason);

  core::Bus& bus_;
  PpaNodeParams params_;
  Ppa array_;
  VisualOdometry vo_;
  TargetExtractor extractor_;
  GateTracker gate_tracker_;
  PpaHost host_;
  nodes::FlightInputs inputs_;
  std::optional<msg::Pose> first_truth_;
  // The last position estimated (not before the host had a height).
  std::optional<Eigen::Vector3d> last_p_ned_m_;
  // Reset requests taken since the last frame, applied before the next one
  // (handlers and frames both run on the bus's dispatch thread).
  std::vector<nodes::VoResetRequest> pending_resets_;
  nodes::VoCommandListener commands_;
  int resets_ = 0;
  std::uint64_t frames_ = 0;
  std::uint64_t dropped_images_ = 0;
  std::uint64_t instructions_ = 0;
  std::string first_drop_reason_;
  std::vector<core::Subscription> subscriptions_;
};

}  // namespace nadir::ppa
