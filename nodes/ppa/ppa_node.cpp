#include "nodes/ppa/ppa_node.h"

#include <opencv2/core.hpp>

#include "core/frames.h"
#include "lcmtypes/bus_io.h"

namespace nadir::ppa {
namespace {

void visitArray(core::ParamVisitor& v, PpaParams& array) {
  v.field("analog_noise_sigma", &array.analog_noise_sigma,
          {.doc = "noise of each analog write, counts; 0 = none", .min = 0, .max = 50});
  std::int64_t seed = static_cast<std::int64_t>(array.noise_seed);
  v.field("noise_seed", &seed, {.doc = "seed of the analog noise", .min = 0});
  array.noise_seed = static_cast<std::uint64_t>(seed);
  v.field(
      "pix_response", &array.pix_response,
      {.doc = "PIX response: log (high dynamic range) or linear", .choices = {"log", "linear"}});
  v.field("pix_gain", &array.pix_gain, {.doc = "gain on the light", .min = 0.001, .max = 1000});
}

}  // namespace

void PpaNodeParams::visit(core::ParamVisitor& v) {
  v.field("enabled", &enabled, {.doc = "run the PPA emulator in this scenario"});
  v.field("mode", &mode,
          {.doc = "odometry (VO and target extraction) or gates (gate and slalom patterns)",
           .choices = {"odometry", "gates"}});
  v.field("image_channel", &image_channel, {.doc = "the PPA camera's 256x256 gray images"});
  v.field("info_channel", &info_channel, {.doc = "its camera_info_t (the lens)"});
  v.field("range_channel", &range_channel, {.doc = "range_t: height above ground"});
  v.field("attitude_channel", &attitude_channel,
          {.doc = "attitude_t: the flight controller's attitude"});
  v.field("truth_channel", &truth_channel, {.doc = "pose_t read once: the start pose"});
  v.field("pose_channel", &pose_channel, {.doc = "vo_estimate_t out"});
  v.field("odometry_channel", &odometry_channel, {.doc = "ppa_odometry_t out"});
  v.field("target_channel", &target_channel, {.doc = "target_detection_t out"});
  v.field("pattern_channel", &pattern_channel, {.doc = "gate_pattern_t out (mode gates)"});
  v.field("command_channel", &command_channel,
          {.doc = "vo_command_t in: resets for ppa or for every VO node"});
  v.field("target_extraction", &target_extraction,
          {.doc = "run target extraction after the odometry on every frame"});
  v.field("chip_instruction_rate_hz", &chip_instruction_rate_hz,
          {.doc = "emulated chip's instruction rate, Hz (processing time = instructions / rate)",
           .min = 1e3,
           .max = 1e12});
  v.group("array", "the emulated SCAMP-5 array",
          [this](core::ParamVisitor& inner) { visitArray(inner, array); });
  core::visitGroup(v, "vo", "on-sensor visual odometry", vo);
  core::visitGroup(v, "target", "on-sensor target extraction", target);
  core::visitGroup(v, "gate", "on-sensor gate and slalom pattern tracking (mode gates)", gate);
  core::visitGroup(v, "host", "pixels to metres, integration, target correction", host);
}

void PpaProcessParams::visit(core::ParamVisitor& v) {
  node.visit(v);
  v.field("known_targets_ne_m", &known_targets_ne_m,
          {.doc = "[north_m, east_m] of the known concentric targets (a scenario's targets)",
           .row_sizes = {2}});
}

PpaNode::PpaNode(core::Bus& bus, const PpaNodeParams& params,
                 std::vector<Eigen::Vector2d> targets_ne_m)
    : bus_(bus),
      params_(params),
      array_(params.array),
      vo_(params.vo),
      extractor_(params.target),
      gate_tracker_(params.gate),
      host_(params.host,
            PpaCamera::fromFov(kWidth, kHeight, params.host.hfov_deg * std::numbers::pi / 180.0,
                               core::rotationBodyFromDownCamera()),
            std::move(targets_ne_m)),
      inputs_(bus, params.range_channel, params.attitude_channel),
      commands_(
          bus, params.command_channel, kSourceName,
          [this](const nodes::VoResetRequest& request) { pending_resets_.push_back(request); }) {
  subscriptions_.push_back(
      msg::subscribe<msg::Pose>(bus_, params_.truth_channel, [this](const msg::Pose& pose) {
        if (!first_truth_) first_truth_ = pose;
      }));
  subscriptions_.push_back(msg::subscribe<msg::CameraInfo>(
      bus_, params_.info_channel, [this](const msg::CameraInfo& info) {
        PpaCamera camera;
        camera.width = info.width;
        camera.height = info.height;
        camera.fx = info.fx;
        camera.fy = info.fy;
        camera.cx = info.cx;
        camera.cy = info.cy;
        camera.R_body_cam = info.q_body_cam.toRotationMatrix();
        host_.setCamera(camera);
      }));
  subscriptions_.push_back(msg::subscribe<msg::Image>(
      bus_, params_.image_channel, [this](const msg::Image& image) { onImage(image); },
      [this](const std::string& reason) { drop(reason); }));
}

void PpaNode::trackPattern(std::int64_t utime, const cv::Mat& gray) {
  array_.setLight(gray.ptr<std::uint8_t>());
  const GateResult result = gate_tracker_.processFrame(array_);
  instructions_ += result.instructions;
  ++frames_;
  msg::GatePattern pattern;
  pattern.utime = utime;
  // GateTracker's PatternKind lists gate_pattern_t's kinds in their order.
  pattern.kind = static_cast<msg::PatternKind>(static_cast<int>(result.kind));
  for (int i = 0; i < result.num_disks; ++i) {
    const auto& disk = result.disk_centres_px[static_cast<std::size_t>(i)];
    pattern.disks_px.emplace_back(disk[0], disk[1]);
  }
  pattern.squares_intact = result.squares_intact;
  pattern.patterns_in_view = result.patterns_in_view;
  pattern.threshold_instructions = static_cast<std::int64_t>(result.stages.threshold);
  pattern.flood_instructions = static_cast<std::int64_t>(result.stages.flood);
  pattern.denoise_instructions = static_cast<std::int64_t>(result.stages.denoise);
  pattern.coordinates_instructions = static_cast<std::int64_t>(result.stages.coordinates);
  pattern.chip_time_s = static_cast<double>(result.instructions) / params_.chip_instruction_rate_hz;
  msg::publish(bus_, params_.pattern_channel, pattern);
}

double PpaNode::meanInstructionsPerFrame() const {
  return frames_ == 0 ? 0.0 : static_cast<double>(instructions_) / static_cast<double>(frames_);
}

void PpaNode::drop(const std::string& reason) {
  if (dropped_images_++ == 0) first_drop_reason_ = reason;
}

void PpaNode::applyResets() {
  for (const nodes::VoResetRequest& request : pending_resets_) {
    ++resets_;
    // The chip takes the next frame as its key-frame; the host anchors it at
    // the position asked for, or at the last estimate. The attitude is the
    // flight controller's either way.
    vo_.reset();
    if (request.T_world_body) {
      host_.initialise(request.T_world_body->translation());
      last_p_ned_m_ = request.T_world_body->translation();
    } else if (last_p_ned_m_) {
      host_.initialise(*last_p_ned_m_);
    }
  }
  pending_resets_.clear();
}

void PpaNode::onImage(const msg::Image& image) {
  cv::Mat gray = image.pixels;
  if (gray.type() != CV_8UC1 || gray.cols != kWidth || gray.rows != kHeight) {
    drop("the PPA needs 256x256 gray images, got " + std::to_string(gray.cols) + "x" +
         std::to_string(gray.rows) + " with " + std::to_string(gray.channels()) + " channel(s)");
    return;
  }
  if (!gray.isContinuous()) gray = gray.clone();
  if (params_.mode == "gates") {
    trackPattern(image.utime, gray);
    return;
  }
  applyResets();
  if (!host_.initialised() && first_truth_ && first_truth_->utime <= image.utime) {
    host_.initialise(first_truth_->p_ned_m);
  }

  array_.setLight(gray.ptr<std::uint8_t>());
  const VisualOdometryResult vo = vo_.processFrame(array_);
  std::optional<TargetExtractionResult> target;
  if (params_.target_extraction) target = extractor_.processFrame(array_);
  // Each program counts its instructions, the controller's loads among them.
  const std::uint64_t instructions = vo.instructions + (target ? target->instructions : 0);
  instructions_ += instructions;
  ++frames_;

  // The attitude at (or just before) the frame.
  const Eigen::Quaterniond q_world_body =
      inputs_.attitudeAt(image.utime).value_or(Eigen::Quaterniond::Identity());
  PpaHostInput input;
  input.utime = image.utime;
  input.alignment = {
      vo.translation_x_px, vo.translation_y_px, vo.rotation_rad,        vo.scale,
      vo.strength,         vo.new_keyframe,     vo.keyframe_edge_count, vo.edge_count};
  input.range_m = inputs_.rangeAt_m(image.utime);
  input.q_world_body = q_world_body;
  // Only a target wholly in view corrects the position: a box cut by the
  // image's border has a shifted centre.
  constexpr int kBorderMarginPx = 2;
  if (target && target->detected && target->box.x_min >= kBorderMarginPx &&
      target->box.y_min >= kBorderMarginPx && target->box.x_max < kWidth - kBorderMarginPx &&
      target->box.y_max < kHeight - kBorderMarginPx) {
    input.target_center_px = Eigen::Vector2d(target->center_x_px, target->center_y_px);
  }
  const PpaHostOutput out = host_.update(input);
  if (out.status != PpaStatus::kInitializing) last_p_ned_m_ = out.p_ned_m;

  msg::VoEstimate estimate;
  estimate.utime = image.utime;
  estimate.source = kSourceName;
  estimate.status = out.status == PpaStatus::kTracking ? msg::VoStatus::TRACKING
                    : out.status == PpaStatus::kLost   ? msg::VoStatus::LOST
                                                       : msg::VoStatus::INITIALIZING;
  estimate.p_ned_m = out.p_ned_m;
  estimate.q_world_body = out.q_world_body;
  estimate.num_features = vo.keyframe_edge_count;
  estimate.num_resets = resets_;
  estimate.processing_time_s = static_cast<double>(instructions) / params_.chip_instruction_rate_hz;
  msg::publish(bus_, params_.pose_channel, estimate);

  msg::PpaOdometry odometry;
  odometry.utime = image.utime;
  odometry.frame_index = static_cast<std::int64_t>(frames_ - 1);
  odometry.translation_x_px = vo.translation_x_px;
  odometry.translation_y_px = vo.translation_y_px;
  odometry.rotation_rad = vo.rotation_rad;
  odometry.scale = vo.scale;
  odometry.strength = vo.strength;
  odometry.new_keyframe = vo.new_keyframe;
  odometry.keyframe_edge_count = vo.keyframe_edge_count;
  odometry.instruction_count = static_cast<std::int64_t>(instructions);
  msg::publish(bus_, params_.odometry_channel, odometry);

  if (target) {
    msg::TargetDetection detection;
    detection.utime = image.utime;
    detection.kind = msg::TargetKind::CONCENTRIC;
    detection.detected = target->detected;
    detection.num_boundaries = params_.target.boundaries;
    if (target->detected) {
      detection.x_min_px = target->box.x_min;
      detection.y_min_px = target->box.y_min;
      detection.x_max_px = target->box.x_max;
      detection.y_max_px = target->box.y_max;
      detection.center_x_px = target->center_x_px;
      detection.center_y_px = target->center_y_px;
    }
    msg::publish(bus_, params_.target_channel, detection);
  }
}

}  // namespace nadir::ppa
