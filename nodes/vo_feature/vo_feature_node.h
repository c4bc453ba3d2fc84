#pragma once
// nadir-vo-feature's work on a bus, the same in the live node and in `nadir
// run`: the downward camera's frames go through FeatureVo with the
// rangefinder's range (and optionally the flight controller's attitude as a
// prior), and vo_estimate_t goes out on POSE_VO_FEATURE. A RESET on
// VO_COMMAND restarts the VO at the next frame. Bad messages are dropped and
// counted.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/bus.h"
#include "core/params.h"
#include "lcmtypes/image.h"
#include "lcmtypes/messages.h"
#include "nodes/common/vo_command.h"
#include "nodes/common/vo_frame_source.h"
#include "nodes/vo_feature/feature_vo.h"

namespace nadir::vo {

// The node's name: its scenario group, its source name in vo_estimate_t and the metrics.
inline constexpr char kFeatureSourceName[] = "vo_feature";

struct VoFeatureNodeParams {
  // In a scenario: run the feature VO (nadir run composes it, nadir launch starts
  // nadir-vo-feature).
  bool enabled = false;
  std::string image_channel = "CAMERA_DOWN";
  std::string info_channel = "CAMERA_DOWN_INFO";
  std::string range_channel = "RANGE";
  std::string attitude_channel = "NAV_ATTITUDE";
  // Read once: the start pose the estimate is anchored to.
  std::string truth_channel = "POSE_TRUTH";
  std::string pose_channel = "POSE_VO_FEATURE";
  // The debug image (the thesis's figure 21): every this many frames (0: none),
  // as JPEG of this quality.
  std::string debug_channel = "VO_FEATURE_DEBUG";
  // vo_command_t in: resets addressed to vo_feature or to every VO node.
  std::string command_channel = "VO_COMMAND";
  int debug_every_frames = 10;
  int debug_jpeg_quality = 80;
  // Use the flight controller's attitude as a prior for each frame's rotation.
  bool attitude_prior = false;
  // Publish the wall-clock processing time in vo_estimate_t (live); off, it is
  // 0 so that runs are byte-identical (nadir run turns it off).
  bool wall_clock_timing = true;
  FeatureVoParams vo;

  void visit(core::ParamVisitor& v);
};

class VoFeatureNode {
 public:
  VoFeatureNode(core::Bus& bus, const VoFeatureNodeParams& params);

  std::uint64_t frames() const { return frames_; }
  std::uint64_t droppedImages() const { return dropped_images_; }
  const std::string& firstDropReason() const { return first_drop_reason_; }
  // Wall-clock seconds spent in FeatureVo::process, over all frames.
  double processingSeconds() const { return processing_s_; }
  const FeatureVoTiming& timing() const { return vo_.timing(); }
  const FeatureVo& vo() const { return vo_; }
  const nodes::VoCommandListener& commands() const { return commands_; }
  // num_resets starts here (a process restarted after one that died).
  void continueResetCount(int resets_before) { resets_before_ = resets_before; }

 private:
  void onImage(const msg::Image& image);
  void applyResets();
  void drop(const std::string& reason);
  void publishDebugImage(const cv::Mat& frame, std::int64_t utime, const VoFrameOutput& out);

  core::Bus& bus_;
  VoFeatureNodeParams params_;
  FeatureVo vo_;
  nodes::VoFrameSource source_;
  // Reset requests taken since the last frame, applied before the next one
  // (handlers and frames both run on the bus's dispatch thread).
  std::vector<nodes::VoResetRequest> pending_resets_;
  int resets_before_ = 0;
  nodes::VoCommandListener commands_;
  bool started_ = false;
  std::uint64_t frames_ = 0;
  std::uint64_t dropped_images_ = 0;
  double processing_s_ = 0.0;
  std::string first_drop_reason_;
  std::vector<core::Subscription> subscriptions_;
};

}  // namespace nadir::vo
