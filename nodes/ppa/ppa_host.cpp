#include "nodes/ppa/ppa_host.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace nadir::ppa {

void PpaHostParams::visit(core::ParamVisitor& v) {
  v.field("hfov_deg", &hfov_deg,
          {.doc = "lens horizontal field of view, deg, until camera_info_t arrives",
           .min = 1,
           .max = 170});
  v.field("scale_correction", &scale_correction,
          {.doc = "McConville et al.'s (2020) f(h): factor on measured distances",
           .min = 0.1,
           .max = 10});
  v.field("target_gate_m", &target_gate_m,
          {.doc = "correct on a known target within this distance of the estimate, m; 0 = off",
           .min = 0,
           .max = 1000});
  v.field("min_keyframe_edges", &min_keyframe_edges,
          {.doc = "fewer key-frame edge pixels than this: LOST", .min = 1, .max = 65536});
  v.field("min_strength_above_chance", &min_strength_above_chance,
          {.doc = "LOST when the alignment's strength is less than this above a random edge "
                  "image's, (strength - edge density) / (1 - edge density)",
           .min = 0,
           .max = 1});
}

PpaCamera PpaCamera::fromFov(int width, int height, double hfov_rad,
                             const Eigen::Matrix3d& R_body_cam) {
  PpaCamera camera;
  camera.width = width;
  camera.height = height;
  camera.fx = camera.fy = 0.5 * width / std::tan(0.5 * hfov_rad);
  camera.cx = 0.5 * (width - 1);
  camera.cy = 0.5 * (height - 1);
  camera.R_body_cam = R_body_cam;
  return camera;
}

PpaHost::PpaHost(const PpaHostParams& params, const PpaCamera& camera,
                 std::vector<Eigen::Vector2d> targets_ne_m)
    : params_(params), camera_(camera), targets_ne_m_(std::move(targets_ne_m)) {
  core::validateParams([this](core::ParamVisitor& v) { params_.visit(v); }, "ppa.host");
}

void PpaHost::initialise(const Eigen::Vector3d& p_ned_m) {
  start_ned_m_ = p_ned_m;
  initialised_ = true;
  keyframe_.reset();
}

Eigen::Vector2d PpaHost::groundOffset(const Eigen::Vector2d& px,
                                      const Eigen::Matrix3d& R_world_body, double height_m) const {
  const Eigen::Vector3d ray_cam((px.x() - camera_.cx) / camera_.fx,
                                (px.y() - camera_.cy) / camera_.fy, 1.0);
  const Eigen::Vector3d ray_world = R_world_body * camera_.R_body_cam * ray_cam;
  // Rays at or above the horizon never meet the ground; treat them as straight down.
  if (ray_world.z() <= 1e-6) return Eigen::Vector2d::Zero();
  return params_.scale_correction * height_m / ray_world.z() *
         Eigen::Vector2d(ray_world.x(), ray_world.y());
}

Eigen::Vector2d PpaHost::nadirPixel(const Eigen::Matrix3d& R_world_body) const {
  const Eigen::Vector3d down_cam =
      (R_world_body * camera_.R_body_cam).transpose() * Eigen::Vector3d::UnitZ();
  return {camera_.cx + camera_.fx * down_cam.x() / down_cam.z(),
          camera_.cy + camera_.fy * down_cam.y() / down_cam.z()};
}

Eigen::Vector2d PpaHost::keyframePixel(const PpaAlignment& alignment,
                                       const Eigen::Vector2d& px) const {
  // The chip's transform: a current-frame pixel p appears in the key-frame at
  // c + t + s R(rotation) (p - c), c the image centre.
  const Eigen::Vector2d centre(camera_.cx, camera_.cy);
  const double c = std::cos(alignment.rotation_rad), s = std::sin(alignment.rotation_rad);
  const Eigen::Vector2d d = px - centre;
  const Eigen::Vector2d rotated(c * d.x() - s * d.y(), s * d.x() + c * d.y());
  return centre + Eigen::Vector2d(alignment.translation_x_px, alignment.translation_y_px) +
         alignment.scale * rotated;
}

PpaHostOutput PpaHost::update(const PpaHostInput& input) {
  PpaHostOutput out;
  out.q_world_body = input.q_world_body;
  if (!initialised_) return out;
  const Eigen::Matrix3d R = input.q_world_body.toRotationMatrix();
  // Height above ground from the slant range along the body-down ray.
  if (input.range_m) last_height_m_ = *input.range_m * std::max(R(2, 2), 0.0);
  if (!last_height_m_) return out;
  const double height_m = *last_height_m_;
  out.height_m = height_m;

  if (!keyframe_) {
    keyframe_ = Keyframe{start_ned_m_, R, height_m, input.alignment.keyframe_edge_count};
  }
  // The point below the vehicle, seen now, found in the key-frame and cast
  // back onto the ground from the key-frame's pose.
  const Eigen::Vector2d below_px = nadirPixel(R);
  const Eigen::Vector2d in_keyframe_px = keyframePixel(input.alignment, below_px);
  const Eigen::Vector2d offset_m =
      groundOffset(in_keyframe_px, keyframe_->R_world_body, keyframe_->height_m);
  out.p_ned_m = keyframe_->p_ned_m + Eigen::Vector3d(offset_m.x(), offset_m.y(), 0.0);
  // Down: the key-frame's ground level, with the height measured now.
  out.p_ned_m.z() = keyframe_->p_ned_m.z() + keyframe_->height_m - height_m;

  if (input.target_center_px && params_.target_gate_m > 0.0 && !targets_ne_m_.empty()) {
    const Eigen::Vector2d to_target_m = groundOffset(*input.target_center_px, R, height_m);
    const Eigen::Vector2d seen_at = out.p_ned_m.head<2>() + to_target_m;
    const Eigen::Vector2d* nearest = nullptr;
    double nearest_m = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector2d& target : targets_ne_m_) {
      const double distance = (target - seen_at).norm();
      if (distance < nearest_m) {
        nearest_m = distance;
        nearest = &target;
      }
    }
    if (nearest != nullptr && nearest_m <= params_.target_gate_m) {
      // McConville et al. (2020) section 3.2: the target's known position, zero error in the
      // distance.
      const Eigen::Vector2d corrected = *nearest - to_target_m;
      out.correction_m =
          Eigen::Vector3d(corrected.x() - out.p_ned_m.x(), corrected.y() - out.p_ned_m.y(), 0.0);
      out.corrected = true;
      out.p_ned_m += out.correction_m;
      keyframe_->p_ned_m += out.correction_m;
    }
  }
  const bool featureless = keyframe_->edges < params_.min_keyframe_edges &&
                           input.alignment.keyframe_edge_count < params_.min_keyframe_edges;
  const double pixels = static_cast<double>(camera_.width) * camera_.height;
  const double edge_density =
      pixels > 0 ? std::clamp(input.alignment.edge_count / pixels, 0.0, 1.0) : 0.0;
  out.strength_above_chance =
      edge_density < 1.0 ? (input.alignment.strength - edge_density) / (1.0 - edge_density) : 0.0;
  const bool unaligned = out.strength_above_chance < params_.min_strength_above_chance;
  out.status = featureless || unaligned ? PpaStatus::kLost : PpaStatus::kTracking;
  if (input.alignment.new_keyframe) {
    keyframe_ = Keyframe{out.p_ned_m, R, height_m, input.alignment.keyframe_edge_count};
  }
  return out;
}

}  // namespace nadir::ppa
