#include "nodes/vo_direct/vo_direct_node.h"

#include <chrono>
#include <cstdio>
#include <variant>

#include "core/stage_times.h"
#include "lcmtypes/bus_io.h"
#include "nodes/vo_direct/debug_image.h"

namespace nadir::vo {
namespace {

// The VO's own stage clocks for one frame, as stages of the run's profile.
void addStageTimes(const DirectVoTiming& before, const DirectVoTiming& after) {
  if (!core::stageTimesEnabled()) return;
  core::addStageTime("pyramid", after.pyramid_s - before.pyramid_s);
  core::addStageTime("track", after.track_s - before.track_s);
  if (after.keyframe_s > before.keyframe_s)
    core::addStageTime("key-frame", after.keyframe_s - before.keyframe_s);
  if (after.window_s > before.window_s)
    core::addStageTime("window optimisation", after.window_s - before.window_s);
}

}  // namespace

void VoDirectNodeParams::visit(core::ParamVisitor& v) {
  v.field("enabled", &enabled, {.doc = "run the direct VO in this scenario"});
  v.field("image_channel", &image_channel, {.doc = "the camera's images (gray or RGB)"});
  v.field("info_channel", &info_channel, {.doc = "its camera_info_t (intrinsics, mount)"});
  v.field("range_channel", &range_channel,
          {.doc = "range_t: the rangefinder along the body's down axis, for the scale"});
  v.field("attitude_channel", &attitude_channel,
          {.doc = "attitude_t: the flight controller's attitude (not used by vision alone)"});
  v.field("truth_channel", &truth_channel, {.doc = "pose_t read once: the start pose"});
  v.field("pose_channel", &pose_channel, {.doc = "vo_estimate_t out"});
  v.field("debug_channel", &debug_channel,
          {.doc = "image_t out: the key-frame's points by inverse depth (thesis figure 20)"});
  v.field("command_channel", &command_channel,
          {.doc = "vo_command_t in: resets for vo_direct or for every VO node"});
  v.field("debug_every_frames", &debug_every_frames,
          {.doc = "a debug image every this many frames (0: none)", .min = 0, .max = 1000000});
  v.field("debug_jpeg_quality", &debug_jpeg_quality,
          {.doc = "JPEG quality of the debug image", .min = 1, .max = 100});
  v.field("wall_clock_timing", &wall_clock_timing,
          {.doc = "publish wall-clock processing time (0 keeps runs byte-identical)"});
  core::visitGroup(v, "vo", "the direct visual odometry", vo);
}

VoDirectNode::VoDirectNode(core::Bus& bus, const VoDirectNodeParams& params)
    : bus_(bus),
      params_(params),
      vo_(params.vo),
      source_(bus,
              {.info_channel = params.info_channel,
               .range_channel = params.range_channel,
               .attitude_channel = params.attitude_channel,
               .truth_channel = params.truth_channel},
              [this](const Eigen::Isometry3d& T_world_body) {
                if (started_) return;
                vo_.setStartPose(T_world_body);
                started_ = true;
              }),
      commands_(
          bus, params.command_channel, kDirectSourceName,
          [this](const nodes::VoResetRequest& request) { pending_resets_.push_back(request); }) {
  subscriptions_.push_back(msg::subscribe<msg::Image>(
      bus_, params_.image_channel, [this](const msg::Image& image) { onImage(image); },
      [this](const std::string& reason) { drop(reason); }));
}

void VoDirectNode::drop(const std::string& reason) {
  if (dropped_images_++ == 0) first_drop_reason_ = reason;
}

void VoDirectNode::onImage(const msg::Image& image) {
  const core::ScopedStage stage("vo_direct");
  for (const nodes::VoResetRequest& request : pending_resets_) {
    if (request.T_world_body && !started_) {
      // A pose given stands for the start pose the truth would give.
      vo_.setStartPose(*request.T_world_body);
      started_ = true;
    }
    vo_.requestReset(request.T_world_body);
  }
  pending_resets_.clear();
  auto made = source_.frame(image, false);
  if (const std::string* reason = std::get_if<std::string>(&made)) {
    if (!reason->empty()) drop(*reason);  // empty: the lens or the start pose has not come yet
    return;
  }
  if (!started_) return;
  const VoFrameInput& input = std::get<VoFrameInput>(made);

  const auto started = std::chrono::steady_clock::now();
  DirectVoOutput out;
  {
    const core::ScopedStage process_stage("process");
    const DirectVoTiming before = vo_.timing();
    out = vo_.process(input);
    addStageTimes(before, vo_.timing());
  }
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  processing_s_ += elapsed_s;
  ++frames_;

  msg::VoEstimate estimate;
  estimate.utime = image.utime;
  estimate.source = kDirectSourceName;
  estimate.status = nodes::wireStatus(out.status);
  estimate.p_ned_m = out.T_world_body.translation();
  estimate.q_world_body = Eigen::Quaterniond(out.T_world_body.rotation());
  estimate.num_features = out.points;
  estimate.num_resets = resets_before_ + out.resets;
  estimate.processing_time_s = params_.wall_clock_timing ? elapsed_s : 0.0;
  msg::publish(bus_, params_.pose_channel, estimate);
  if (params_.debug_every_frames > 0 &&
      (frames_ - 1) % static_cast<std::uint64_t>(params_.debug_every_frames) == 0)
    publishDebugImage(image.utime, out);
}

void VoDirectNode::publishDebugImage(std::int64_t utime, const DirectVoOutput& out) {
  const core::ScopedStage stage("debug image");
  if (vo_.keyframeImage().empty()) return;
  char text[160];
  std::snprintf(text, sizeof text,
                "%s  %d points aligned  window %d key-frames %d points  resets %d  log gain %+.3f",
                nodes::statusName(out.status), out.points, vo_.numKeyframes(), vo_.numPoints(),
                out.resets, out.affine.a);
  msg::publish(bus_, params_.debug_channel,
               msg::Image{utime,
                          drawDirectDebugImage(vo_.keyframeImage(), vo_.keyframePoints(), text),
                          params_.debug_jpeg_quality,
                          {}});
}

}  // namespace nadir::vo
