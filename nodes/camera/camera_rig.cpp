#include "nodes/camera/camera_rig.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <numbers>
#include <stdexcept>

#include "calib/calibration_file.h"
#include "core/frames.h"
#include "core/hash.h"

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
  v.field("calibration_file", &calibration_file,
          {.doc = "calibration YAML (nadir calib) announced as the lens; empty: the true lens"});
  v.field("time_offset_s", &time_offset_s,
          {.doc = "stamp minus the true time of each frame, s", .min = -1, .max = 1});
  v.field("timestamp_jitter_s", &timestamp_jitter_s,
          {.doc = "Gaussian jitter of the stamps, 1 sigma, s", .min = 0, .max = 0.1});
  v.field("jitter_seed", &jitter_seed, {.doc = "seed of the stamps' jitter"});
}

std::int64_t CameraSpec::stampOf(std::int64_t true_utime) const {
  double jitter_s = 0.0;
  if (timestamp_jitter_s > 0.0) {
    // Box-Muller on two draws of splitmix64 from the seed and the frame's time.
    const std::uint64_t key = static_cast<std::uint64_t>(jitter_seed) * 0x9E3779B97F4A7C15ull ^
                              static_cast<std::uint64_t>(true_utime);
    const double u1 = core::uniformOpen01(core::splitmix64(key));
    const double u2 = core::uniformOpen01(core::splitmix64(key + 0x9E3779B97F4A7C15ull));
    const double gaussian = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
    jitter_s = timestamp_jitter_s * std::clamp(gaussian, -3.0, 3.0);
  }
  return true_utime + std::llround((time_offset_s + jitter_s) * 1e6);
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
  for (auto& entry : specs_) {
    const std::string& name = entry.first;
    CameraSpec& spec = entry.second;
    core::validateParams([&spec](core::ParamVisitor& v) { spec.visit(v); }, "cameras." + name);
    Camera camera;
    camera.renderer = std::make_unique<render::CameraRenderer>(terrain, spec.camera);
    camera.half_span_us = core::utimeFromSeconds(spec.camera.motionHalfSpan_s());
    if (!spec.calibration_file.empty()) camera.calibrated = readCalibratedLens(name, spec);
    if (camera.half_span_us > 0)
      history_span_us_ = std::max(history_span_us_, 2 * camera.half_span_us + 200000);
    cameras_.emplace(name, std::move(camera));
  }
}

void CameraRig::reset() {
  for (auto& [name, camera] : cameras_) {
    camera.next_due_utime = core::kDueAtFirstCall;
    camera.waiting.clear();
  }
  history_.clear();
  last_utime_ = -1;
}

Eigen::Isometry3d CameraRig::poseAt(std::int64_t utime) const {
  if (utime <= history_.front().utime) return history_.front().T_world_body;
  if (utime >= history_.back().utime) return history_.back().T_world_body;
  const auto after =
      std::lower_bound(history_.begin(), history_.end(), utime,
                       [](const StampedPose& pose, std::int64_t t) { return pose.utime < t; });
  const auto before = std::prev(after);
  const double f = static_cast<double>(utime - before->utime) /
                   static_cast<double>(after->utime - before->utime);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(before->T_world_body.rotation())
                   .slerp(f, Eigen::Quaterniond(after->T_world_body.rotation()))
                   .toRotationMatrix();
  T.translation() =
      (1.0 - f) * before->T_world_body.translation() + f * after->T_world_body.translation();
  return T;
}

render::CameraMotion CameraRig::motionAt(std::int64_t utime, std::int64_t half_span_us,
                                         const Eigen::Isometry3d& T_body_cam) const {
  const std::int64_t t_a = std::max(utime - half_span_us, history_.front().utime);
  const std::int64_t t_b = std::min(utime + half_span_us, history_.back().utime);
  render::CameraMotion motion;
  if (t_b <= t_a) return motion;
  const double dt_s = static_cast<double>(t_b - t_a) * 1e-6;
  const Eigen::Isometry3d T_cam_a = poseAt(t_a) * T_body_cam;
  const Eigen::Isometry3d T_cam_b = poseAt(t_b) * T_body_cam;
  const Eigen::Isometry3d T_cam = poseAt(utime) * T_body_cam;
  const Eigen::AngleAxisd turn(T_cam_a.rotation().transpose() * T_cam_b.rotation());
  motion.omega_cam_rps = turn.axis() * (turn.angle() / dt_s);
  motion.v_cam_mps =
      T_cam.rotation().transpose() * (T_cam_b.translation() - T_cam_a.translation()) / dt_s;
  return motion;
}

std::vector<CameraFrame> CameraRig::onPose(std::int64_t utime,
                                           const Eigen::Isometry3d& T_world_body) {
  if (utime < last_utime_) reset();
  last_utime_ = utime;
  history_.push_back({utime, T_world_body});
  while (history_.size() > 2 && history_[1].utime <= utime - history_span_us_) history_.pop_front();
  std::vector<CameraFrame> frames;
  for (auto& [name, camera] : cameras_) {
    const CameraSpec& spec = specs_.at(name);
    // Due times sit on a fixed grid, so a late pose does not shift later frames.
    if (core::due(utime, spec.fps, camera.next_due_utime)) camera.waiting.push_back(utime);
    while (!camera.waiting.empty() && camera.waiting.front() + camera.half_span_us <= utime) {
      const std::int64_t frame_utime = camera.waiting.front();
      camera.waiting.pop_front();
      const Eigen::Isometry3d T_body_cam = spec.T_body_cam();
      const render::CameraMotion motion =
          camera.half_span_us > 0 ? motionAt(frame_utime, camera.half_span_us, T_body_cam)
                                  : render::CameraMotion{};
      render::RenderedImage rendered =
          camera.renderer->render(poseAt(frame_utime) * T_body_cam, frame_utime, false, motion);
      rendered.utime = spec.stampOf(frame_utime);
      frames.push_back({name, &spec, std::move(rendered)});
    }
  }
  return frames;
}

const render::CameraIntrinsics& CameraRig::intrinsics(const std::string& name) const {
  return cameras_.at(name).renderer->intrinsics();
}

const render::CameraIntrinsics& CameraRig::announcedIntrinsics(const std::string& name) const {
  const Camera& camera = cameras_.at(name);
  return camera.calibrated ? *camera.calibrated : camera.renderer->intrinsics();
}

render::CameraIntrinsics readCalibratedLens(const std::string& name, const CameraSpec& spec) {
  const std::string where = "camera " + name + ": calibration_file " + spec.calibration_file;
  render::CameraIntrinsics lens;
  try {
    lens = calib::toCameraIntrinsics(calib::readCalibrationFile(spec.calibration_file));
  } catch (const std::exception& error) {
    throw std::runtime_error(where + ": " + error.what());
  }
  if (lens.width != spec.camera.width || lens.height != spec.camera.height) {
    throw std::runtime_error(where + " is for " + std::to_string(lens.width) + "x" +
                             std::to_string(lens.height) + " images, the camera makes " +
                             std::to_string(spec.camera.width) + "x" +
                             std::to_string(spec.camera.height));
  }
  return lens;
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
  info.time_offset_s = spec.time_offset_s;
  info.timestamp_jitter_s = spec.timestamp_jitter_s;
  info.exposure_s = spec.camera.motion_blur ? spec.camera.exposure_s : 0.0;
  info.readout_s = spec.camera.rolling_shutter ? spec.camera.readout_s : 0.0;
  return info;
}

}  // namespace nadir::camera
