#pragma once
// nadir-camera's work on a bus, the same in the live node and in `nadir run`:
// true poses in, each due camera's image and (with the first frame, then once
// a second) its camera_info_t out. Bad poses are dropped and counted.

#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include "core/bus.h"
#include "lcmtypes/messages.h"
#include "nodes/camera/camera_node_params.h"
#include "nodes/camera/camera_rig.h"
#include "nodes/camera/ground_scene.h"

namespace nadir::camera {

class CameraNode {
 public:
  // Builds the world, the GL context and the cameras (the context stays
  // current on this thread), then subscribes to params.pose_channel.
  CameraNode(core::Bus& bus, const CameraNodeParams& params);

  // Called with every frame as it is published (in this process: the image
  // itself, no copy of its pixels), before the bus delivers it.
  void onFrame(std::function<void(const CameraFrame&)> observer) {
    observer_ = std::move(observer);
  }

  const GroundScene& scene() const { return scene_; }
  std::uint64_t framesPublished() const { return frames_; }
  std::uint64_t badPoses() const { return bad_poses_; }
  // The first bad pose's problem, for the log; empty if none.
  const std::string& firstBadPose() const { return first_bad_pose_; }

 private:
  void onPose(const msg::Pose& pose);
  void dropPose(const std::string& reason);

  core::Bus& bus_;
  GroundScene scene_;
  CameraRig rig_;
  std::map<std::string, std::int64_t> last_info_utime_;
  std::uint64_t frames_ = 0;
  std::uint64_t bad_poses_ = 0;
  std::string first_bad_pose_;
  std::function<void(const CameraFrame&)> observer_;
  core::Subscription subscription_;
};

}  // namespace nadir::camera
