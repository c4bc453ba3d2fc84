#include "nodes/camera/camera_rig.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "core/frames.h"

namespace nadir::camera {

void CameraSpec::visit(core::ParamVisitor& v) {
  camera.visit(v);
  v.field("channel", &channel, {.doc = "image channel"});
  v.field("info_channel", &info_channel, {.doc = "camera_info_t channel"});
  v.field("fps", &fps, {.doc = "frame rate in message time, Hz", .min = 0.1, .max = 2000});
  v.field(
      "mount_position_m", &mount_position_m,
      {.doc = "optical centre in the body FRD frame, m", .min = -100, .max = 100, .list_size = 3});
  v.field("mount_rpy_deg", &mount_rpy_deg,
          {.doc = "roll pitch yaw of the mount from straight down, image top to the nose, deg",
           .min = -180,
           .max = 180,
           .list_size = 3});
  v.field("jpeg_quality", &jpeg_quality,
          {.doc = "0 sends raw pixels, 1-100 JPEG of that quality", .min = 0, .max = 100});
}

Eigen::Isometry3d CameraSpec::T_body_cam() const {
  constexpr double kDeg = std::numbers::pi / 180.0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = core::rotationFromRpy(
                   {mount_rpy_deg[0] * kDeg, mount_rpy_deg[1] * kDeg, mount_rpy_deg[2] * kDeg}) *
               core::rotationBodyFromDownCamera();
  T.translation() = Eigen::Vector3d(mount_position_m[0], mount_position_m[1], mount_position_m[2]);
  return T;
}

CameraRig::CameraRig(render::TerrainRenderer& terrain,
                     const std::map<std::string, CameraSpec>& cameras)
    : specs_(cameras) {
  if (specs_.empty()) throw std::invalid_argument("the camera rig has no camera");
  for (auto& [name, spec] : specs_) {
    core::validateParams([&spec](core::ParamVisitor& v) { spec.visit(v); }, "cameras." + name);
    Camera camera;
    camera.renderer = std::make_unique<render::CameraRenderer>(terrain, spec.camera);
    cameras_.emplace(name, std::move(camera));
  }
}

void CameraRig::reset() {
  for (auto& [name, camera] : cameras_) camera.next_due_utime = core::kDueAtFirstCall;
  last_utime_ = -1;
}

std::vector<CameraFrame> CameraRig::onPose(std::int64_t utime,
                                           const Eigen::Isometry3d& T_world_body) {
  if (utime < last_utime_) reset();
  last_utime_ = utime;
  std::vector<CameraFrame> frames;
  for (auto& [name, camera] : cameras_) {
    const CameraSpec& spec = specs_.at(name);
    // Due times sit on a fixed grid, so a late pose does not shift later frames.
    if (!core::due(utime, spec.fps, camera.next_due_utime)) continue;
    frames.push_back(
        {name, &spec, camera.renderer->render(T_world_body * spec.T_body_cam(), utime)});
  }
  return frames;
}

const render::CameraIntrinsics& CameraRig::intrinsics(const std::string& name) const {
  return cameras_.at(name).renderer->intrinsics();
}

msg::CameraInfo cameraInfo(const std::string& name, const CameraSpec& spec,
                           const render::CameraIntrinsics& intrinsics, std::int64_t utime) {
  msg::CameraInfo info;
  info.utime = utime;
  info.camera_name = name;
  info.width = intrinsics.width;
  info.height = intrinsics.height;
  info.fx = intrinsics.fx;
  info.fy = intrinsics.fy;
  info.cx = intrinsics.cx;
  info.cy = intrinsics.cy;
  info.distortion_model =
      intrinsics.hasDistortion() ? msg::Distortion::RADTAN : msg::Distortion::NONE;
  info.distortion.assign(intrinsics.distortion.begin(), intrinsics.distortion.end());
  info.fps = spec.fps;
  const Eigen::Isometry3d T_body_cam = spec.T_body_cam();
  info.p_cam_in_body_m = T_body_cam.translation();
  info.q_body_cam = Eigen::Quaterniond(T_body_cam.rotation());
  return info;
}

}  // namespace nadir::camera
