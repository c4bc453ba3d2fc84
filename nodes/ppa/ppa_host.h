#pragma once
// The host side of the PPA's visual odometry (McConville et al. 2020, section 2.3.1,
// equations 1-5): the chip reports how the current frame aligns to its
// key-frame in pixels; the host turns that into metres with the rangefinder's
// height and the lens, removes the apparent motion the vehicle's rotation
// causes using the flight controller's attitude, and integrates the position
// in the local NED frame. A detected target of known position corrects it.
//
// The equations are used in their exact form rather than small-angle: the
// ground point directly below the vehicle now is found in the current image
// (through the current attitude), carried into the key-frame's image by the
// chip's alignment, and cast back onto the ground from the key-frame's pose
// and height. With level flight this is McConville et al.'s (2020) d = h tan(F/2) / 128 * px
// per pixel, minus h tan(attitude change) for rotations, rotated by the yaw.
//
// No LCM: plain structs in and out.

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/params.h"

namespace nadir::ppa {

struct PpaHostParams {
  // Lens field of view, deg, used when no camera_info_t has been received.
  double hfov_deg = 50.0;
  // McConville et al.'s (2020) f(h): a factor on the measured distances (1 for nadir's ideal lens).
  double scale_correction = 1.0;
  // Correct the position when a known target is seen within this distance of
  // where the estimate expects it, m; 0 turns target correction off.
  double target_gate_m = 10.0;
  // A key-frame with fewer edge pixels than this cannot be aligned to (a
  // featureless view): the estimate is LOST until a better one.
  int min_keyframe_edges = 50;
  // The alignment shares strength of the key-frame's edges; an edge image of
  // random pixels would share this frame's edge density by chance (sensor
  // noise above the edge threshold fills it). Below this much above chance,
  // (strength - density) / (1 - density), the alignment is no better than a
  // guess: LOST until it is again.
  double min_strength_above_chance = 0.07;

  void visit(core::ParamVisitor& v);
};

// What the chip reported for one frame (see VisualOdometryResult).
struct PpaAlignment {
  // Aligns the current frame to the key-frame it was compared with: pixels
  // (x right, y down), rotation (rad, clockwise in the image), scale.
  double translation_x_px = 0.0;
  double translation_y_px = 0.0;
  double rotation_rad = 0.0;
  double scale = 1.0;
  double strength = 0.0;
  // This frame becomes the key-frame for the next ones.
  bool new_keyframe = false;
  int keyframe_edge_count = 0;
  // Edge pixels of this frame.
  int edge_count = 0;
};

// A pinhole camera: image size, focal lengths and principal point, pixels.
struct PpaCamera {
  int width = 256;
  int height = 256;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  // R_body_cam: camera optical frame (x right, y down, z along the axis) to body FRD.
  Eigen::Matrix3d R_body_cam = Eigen::Matrix3d::Identity();

  static PpaCamera fromFov(int width, int height, double hfov_rad,
                           const Eigen::Matrix3d& R_body_cam);
};

struct PpaHostInput {
  std::int64_t utime = 0;
  PpaAlignment alignment;
  // Rangefinder distance along the body-down ray, m; nothing when invalid.
  std::optional<double> range_m;
  // The flight controller's attitude at the frame, R_world_body.
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();
  // The target's centre in the image, pixels, when the chip found one.
  std::optional<Eigen::Vector2d> target_center_px;
};

enum class PpaStatus { kInitializing, kTracking, kLost };

struct PpaHostOutput {
  PpaStatus status = PpaStatus::kInitializing;
  Eigen::Vector3d p_ned_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();
  // A known target corrected the position this frame, by this much (NED, m).
  bool corrected = false;
  Eigen::Vector3d correction_m = Eigen::Vector3d::Zero();
  // Height above ground used, m.
  double height_m = 0.0;
  // The alignment's strength above chance (PpaHostParams::min_strength_above_chance).
  double strength_above_chance = 0.0;
};

class PpaHost {
 public:
  // targets_ne_m: known target positions (north, east) in the world frame.
  PpaHost(const PpaHostParams& params, const PpaCamera& camera,
          std::vector<Eigen::Vector2d> targets_ne_m);

  void setCamera(const PpaCamera& camera) { camera_ = camera; }
  // The starting position (the truth when the node starts, as for every VO node).
  void initialise(const Eigen::Vector3d& p_ned_m);
  bool initialised() const { return initialised_; }
  PpaHostOutput update(const PpaHostInput& input);

  // Where the ground point seen at pixel px lies relative to the camera,
  // north and east, m, for a camera at height_m above flat ground with attitude R_world_body.
  Eigen::Vector2d groundOffset(const Eigen::Vector2d& px, const Eigen::Matrix3d& R_world_body,
                               double height_m) const;
  // The pixel at which a camera with attitude R_world_body sees the point straight below it.
  Eigen::Vector2d nadirPixel(const Eigen::Matrix3d& R_world_body) const;
  // The key-frame pixel the chip's alignment maps a current-frame pixel to.
  Eigen::Vector2d keyframePixel(const PpaAlignment& alignment, const Eigen::Vector2d& px) const;

 private:
  struct Keyframe {
    Eigen::Vector3d p_ned_m;
    Eigen::Matrix3d R_world_body;
    double height_m;
    int edges;
  };

  PpaHostParams params_;
  PpaCamera camera_;
  std::vector<Eigen::Vector2d> targets_ne_m_;
  bool initialised_ = false;
  Eigen::Vector3d start_ned_m_ = Eigen::Vector3d::Zero();
  std::optional<Keyframe> keyframe_;
  std::optional<double> last_height_m_;
};

}  // namespace nadir::ppa
