#include "nodes/camera/camera_node.h"

#include <stdexcept>

#include "nodes/camera/camera_messages.h"

namespace nadir::camera {

CameraNode::CameraNode(core::Bus& bus, const CameraNodeParams& params)
    : bus_(bus),
      scene_(params.world, params.tiles, params.renderer, params.targets),
      rig_(scene_.terrain, params.cameras) {
  subscription_ = core::subscribe<nadir::pose_t>(
      bus_, params.pose_channel, [this](const nadir::pose_t& pose) { onPose(pose); });
}

void CameraNode::onPose(const nadir::pose_t& pose) {
  Eigen::Isometry3d T_world_body;
  try {
    T_world_body = bodyPoseFromMessage(pose);
  } catch (const std::invalid_argument& error) {
    if (bad_poses_++ == 0) first_bad_pose_ = error.what();
    return;
  }
  for (const CameraFrame& frame : rig_.onPose(pose.utime, T_world_body)) {
    core::publish(bus_, frame.spec->channel,
                  toImageMessage(frame.rendered, frame.spec->jpeg_quality));
    // camera_info_t with the first frame, then once a second (and after a jump back).
    auto [last, first] = last_info_utime_.try_emplace(frame.name, pose.utime);
    if (first || pose.utime - last->second >= 1'000'000 || pose.utime < last->second) {
      core::publish(bus_, frame.spec->info_channel,
                    toCameraInfo(frame.name, *frame.spec, rig_.intrinsics(frame.name), pose.utime));
      last->second = pose.utime;
    }
    ++frames_;
  }
}

}  // namespace nadir::camera
