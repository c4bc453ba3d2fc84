#include "nodes/vo_feature/vo_feature_node.h"

#include <sstream>
#include <variant>

#include "core/frames.h"
#include "core/stage_times.h"
#include "lcmtypes/bus_io.h"

namespace nadir::vo {
namespace {

// The VO's own stage clocks for one frame, as stages of the run's profile.
void addStageTimes(const FeatureVoTiming& before, const FeatureVoTiming& after) {
  if (!core::stageTimesEnabled()) return;
  core::addStageTime("extract", after.extract_s - before.extract_s);
  core::addStageTime("track", after.track_s - before.track_s);
  if (after.keyframes > before.keyframes)
    core::addStageTime("key-frame", after.mapping_s - before.mapping_s);
}

}  // namespace

void VoFeatureNodeParams::visit(core::ParamVisitor& v) {
  v.field("enabled", &enabled, {.doc = "run the feature VO in this scenario"});
  v.field("image_channel", &image_channel, {.doc = "the camera's images (gray or RGB)"});
  v.field("info_channel", &info_channel, {.doc = "its camera_info_t (intrinsics, mount)"});
  v.field("range_channel", &range_channel,
          {.doc = "range_t: the rangefinder along the body's down axis, for the scale"});
  v.field("attitude_channel", &attitude_channel,
          {.doc = "attitude_t: the flight controller's attitude (for attitude_prior)"});
  v.field("truth_channel", &truth_channel, {.doc = "pose_t read once: the start pose"});
  v.field("pose_channel", &pose_channel, {.doc = "vo_estimate_t out"});
  v.field("debug_channel", &debug_channel,
          {.doc = "image_t out: the frame with the tracked features (thesis figure 21)"});
  v.field("command_channel", &command_channel,
          {.doc = "vo_command_t in: resets for vo_feature or for every VO node"});
  v.field("debug_every_frames", &debug_every_frames,
          {.doc = "a debug image every this many frames (0: none)", .min = 0, .max = 1000000});
  v.field("debug_jpeg_quality", &debug_jpeg_quality,
          {.doc = "JPEG quality of the debug image", .min = 1, .max = 100});
  v.field("attitude_prior", &attitude_prior,
          {.doc = "use the flight controller's attitude as each frame's rotation prior"});
  v.field("wall_clock_timing", &wall_clock_timing,
          {.doc = "publish wall-clock processing time (0 keeps runs byte-identical)"});
  core::visitGroup(v, "vo", "the visual odometry", vo);
}

VoFeatureNode::VoFeatureNode(core::Bus& bus, const VoFeatureNodeParams& params)
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
          bus, params.command_channel, kFeatureSourceName,
          [this](const nodes::VoResetRequest& request) { pending_resets_.push_back(request); }) {
  subscriptions_.push_back(msg::subscribe<msg::Image>(
      bus_, params_.image_channel, [this](const msg::Image& image) { onImage(image); },
      [this](const std::string& reason) { drop(reason); }));
}

void VoFeatureNode::drop(const std::string& reason) {
  if (dropped_images_++ == 0) first_drop_reason_ = reason;
}

void VoFeatureNode::applyResets() {
  for (const nodes::VoResetRequest& request : pending_resets_) {
    vo_.restart(request.T_world_body);
    // A pose given stands for the start pose the truth would give.
    if (request.T_world_body) started_ = true;
  }
  pending_resets_.clear();
}

void VoFeatureNode::onImage(const msg::Image& image) {
  const core::ScopedStage stage("vo_feature");
  applyResets();
  auto made = source_.frame(image, params_.attitude_prior);
  if (const std::string* reason = std::get_if<std::string>(&made)) {
    if (!reason->empty()) drop(*reason);  // empty: the lens or the start pose has not come yet
    return;
  }
  if (!started_) return;
  const VoFrameInput& input = std::get<VoFrameInput>(made);

  const auto started = std::chrono::steady_clock::now();
  VoFrameOutput out;
  {
    const core::ScopedStage process_stage("process");
    const FeatureVoTiming before = vo_.timing();
    out = vo_.process(input);
    addStageTimes(before, vo_.timing());
  }
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  processing_s_ += elapsed_s;
  ++frames_;

  msg::VoEstimate estimate;
  estimate.utime = image.utime;
  estimate.source = kFeatureSourceName;
  estimate.status = nodes::wireStatus(out.status);
  estimate.p_ned_m = out.T_world_body.translation();
  estimate.q_world_body = Eigen::Quaterniond(out.T_world_body.rotation());
  estimate.num_features = out.tracked_points;
  estimate.num_resets = resets_before_ + out.resets;
  estimate.processing_time_s = params_.wall_clock_timing ? elapsed_s : 0.0;
  msg::publish(bus_, params_.pose_channel, estimate);
  if (params_.debug_every_frames > 0 &&
      (frames_ - 1) % static_cast<std::uint64_t>(params_.debug_every_frames) == 0)
    publishDebugImage(input.gray, image.utime, out);
}

void VoFeatureNode::publishDebugImage(const cv::Mat& frame, std::int64_t utime,
                                      const VoFrameOutput& out) {
  const core::ScopedStage stage("debug image");
  const char* status = nodes::statusName(out.status);
  const std::vector<DebugFeature>& features = vo_.lastFrameFeatures();
  std::ostringstream text;
  text << status << "  " << out.tracked_points << " matched of " << features.size()
       << " features  map " << vo_.numMapPoints() << " points  key-frames "
       << vo_.timing().keyframes << "  resets " << out.resets;
  msg::publish(
      bus_, params_.debug_channel,
      msg::Image{
          utime, drawDebugImage(frame, features, text.str()), params_.debug_jpeg_quality, {}});
}

}  // namespace nadir::vo
