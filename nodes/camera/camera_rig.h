#pragma once
// The camera node's algorithm: one or more virtual cameras mounted on a body,
// each rendering at its own frame rate in message time from the body's true
// pose. No LCM here: main.cpp feeds poses in and sends the frames out.

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/clock.h"
#include "core/params.h"
#include "lcmtypes/messages.h"
#include "render/camera_renderer.h"
#include "render/terrain_renderer.h"

namespace nadir::camera {

struct CameraSpec {
  render::CameraParams camera;
  std::string channel = "CAMERA_DOWN";
  std::string info_channel = "CAMERA_DOWN_INFO";
  double fps = 31.0;
  // Camera optical centre in the body FRD frame, m.
  std::vector<double> mount_position_m = {0.0, 0.0, 0.0};
  // Mount rotation relative to looking straight down with the image top towards the
  // nose, as roll, pitch, yaw in deg (body axes, Z-Y-X).
  std::vector<double> mount_rpy_deg = {0.0, 0.0, 0.0};
  // 0 sends raw pixels; 1-100 sends JPEG of that quality (for thin links).
  int jpeg_quality = 0;
  // A calibration file (OpenCV YAML, as nadir calib writes it): the lens the
  // camera announces on its info channel instead of the one it renders with,
  // as a real camera announces its calibration, not its true lens. Empty: the
  // rendering lens.
  std::string calibration_file;
  // Each frame's stamp is its true time plus time_offset_s (the camera's clock
  // against the body's) plus Gaussian jitter of timestamp_jitter_s (1 sigma,
  // cut at 3 sigma, from jitter_seed and the frame's time), s.
  double time_offset_s = 0.0;
  double timestamp_jitter_s = 0.0;
  std::int64_t jitter_seed = 1;

  void visit(core::ParamVisitor& v);
  Eigen::Isometry3d T_body_cam() const;
  // The stamp of a frame whose true time is true_utime.
  std::int64_t stampOf(std::int64_t true_utime) const;
};

struct CameraFrame {
  std::string name;
  const CameraSpec* spec = nullptr;
  render::RenderedImage rendered;
};

class CameraRig {
 public:
  // Needs a current GL context for its whole life.
  CameraRig(render::TerrainRenderer& terrain, const std::map<std::string, CameraSpec>& cameras);

  // A true pose of the body at utime (message time), in time order. Returns
  // the frames that fell due: a camera at f frames/s renders at the first pose
  // at or after each multiple of 1/f s, stamped with that pose's utime (plus
  // the spec's clock offset and jitter; the pose drawn is the true one). With
  // motion blur or rolling shutter on, a frame waits for the poses that cover
  // its exposure (the render's motionHalfSpan_s after it) and moves with the
  // camera's velocity between the poses that half-span before and after it.
  std::vector<CameraFrame> onPose(std::int64_t utime, const Eigen::Isometry3d& T_world_body);

  // Forget frame timing (after a jump back in time, e.g. a log restarted).
  void reset();

  const std::map<std::string, CameraSpec>& cameras() const { return specs_; }
  // The lens a camera renders with.
  const render::CameraIntrinsics& intrinsics(const std::string& name) const;
  // The lens it announces: its calibration_file's, or the rendering lens.
  const render::CameraIntrinsics& announcedIntrinsics(const std::string& name) const;

 private:
  struct Camera {
    std::unique_ptr<render::CameraRenderer> renderer;
    std::optional<render::CameraIntrinsics> calibrated;  // from calibration_file
    std::int64_t next_due_utime = core::kDueAtFirstCall;
    std::int64_t half_span_us = 0;
    std::deque<std::int64_t> waiting;  // due frames' utimes, waiting for later poses
  };
  struct StampedPose {
    std::int64_t utime;
    Eigen::Isometry3d T_world_body;
  };
  // The body pose at utime, interpolated in the history (clamped to its ends).
  Eigen::Isometry3d poseAt(std::int64_t utime) const;
  render::CameraMotion motionAt(std::int64_t utime, std::int64_t half_span_us,
                                const Eigen::Isometry3d& T_body_cam) const;

  std::map<std::string, CameraSpec> specs_;
  std::map<std::string, Camera> cameras_;
  std::deque<StampedPose> history_;
  std::int64_t history_span_us_ = 0;
  std::int64_t last_utime_ = -1;
};

// The lens in a calibration file for a camera of this spec. Throws
// std::runtime_error naming the file and the camera when it cannot be read,
// is a fisheye calibration, or is for another image size than the camera's.
render::CameraIntrinsics readCalibratedLens(const std::string& name, const CameraSpec& spec);

// The camera_info_t of a camera of the rig: its lens and mount, stamped utime.
msg::CameraInfo cameraInfo(const std::string& name, const CameraSpec& spec,
                           const render::CameraIntrinsics& intrinsics, std::int64_t utime);

}  // namespace nadir::camera
