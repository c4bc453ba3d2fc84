#include "nodes/camera/camera_node.h"

#include "core/stage_times.h"
#include "lcmtypes/bus_io.h"

namespace nadir::camera {

CameraNode::CameraNode(core::Bus& bus, const CameraNodeParams& params)
    : bus_(bus),
      scene_(params.world, params.tiles, params.renderer, params.targets, params.course),
      rig_(scene_.terrain, params.cameras) {
  subscription_ = msg::subscribe<msg::Pose>(
      bus_, params.pose_channel, [this](const msg::Pose& pose) { onPose(pose); },
      [this](const std::string& reason) { dropPose(reason); });
}

void CameraNode::dropPose(const std::string& reason) {
  if (bad_poses_++ == 0) first_bad_pose_ = reason;
}

void CameraNode::onPose(const msg::Pose& pose) {
  const core::ScopedStage stage("camera");
  Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
  T_world_body.linear() = pose.q_world_body.toRotationMatrix();
  T_world_body.translation() = pose.p_ned_m;
  for (const CameraFrame& frame : rig_.onPose(pose.utime, T_world_body)) {
    msg::publish(
        bus_, frame.spec->channel,
        msg::Image{frame.rendered.utime, frame.rendered.image, frame.spec->jpeg_quality, {}});
    if (observer_) observer_(frame);
    // camera_info_t with the first frame, then once a second (and after a jump back).
    auto [last, first] = last_info_utime_.try_emplace(frame.name, pose.utime);
    if (first || pose.utime - last->second >= 1'000'000 || pose.utime < last->second) {
      msg::publish(
          bus_, frame.spec->info_channel,
          cameraInfo(frame.name, *frame.spec, rig_.announcedIntrinsics(frame.name), pose.utime));
      last->second = pose.utime;
    }
    ++frames_;
  }
}

}  // namespace nadir::camera
