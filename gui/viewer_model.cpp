#include "gui/viewer_model.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace nadir::gui {
namespace {

// The lines of one trajectory up to t_s, appended to lines.
void appendTrackUpTo(const core::Trajectory& trajectory, double t_s, double max_gap_s,
                     std::vector<std::vector<Eigen::Vector3d>>& lines) {
  std::vector<Eigen::Vector3d> line;
  double last_t = 0.0;
  for (std::size_t i = 0; i < trajectory.size() && trajectory[i].t_s <= t_s; ++i) {
    if (!line.empty() && trajectory[i].t_s - last_t > max_gap_s) {
      lines.push_back(std::move(line));
      line.clear();
    }
    line.push_back(trajectory[i].p_ned_m);
    last_t = trajectory[i].t_s;
  }
  if (const auto now = positionAt(trajectory, t_s, max_gap_s); now && !line.empty()) {
    if ((*now - line.back()).norm() > 0.0) line.push_back(*now);
  }
  if (!line.empty()) lines.push_back(std::move(line));
}

}  // namespace

std::optional<Eigen::Vector3d> positionAt(const core::Trajectory& trajectory, double t_s,
                                          double max_gap_s) {
  const std::optional<core::StampedPose> pose = core::interpolate(trajectory, t_s, max_gap_s);
  if (!pose) return std::nullopt;
  return pose->p_ned_m;
}

std::optional<Eigen::Vector3d> positionAt(const SourceSeries& source, double t_s,
                                          double max_gap_s) {
  for (const core::Trajectory& stretch : source.tracked) {
    if (stretch.front().t_s <= t_s && t_s <= stretch.back().t_s) {
      return positionAt(stretch, t_s, max_gap_s);
    }
  }
  return std::nullopt;
}

std::optional<Eigen::Quaterniond> attitudeAt(const core::Trajectory& trajectory, double t_s,
                                             double max_gap_s) {
  const std::optional<core::StampedPose> pose = core::interpolate(trajectory, t_s, max_gap_s);
  if (!pose) return std::nullopt;
  return pose->q_world_body;
}

std::vector<std::vector<Eigen::Vector3d>> trackUpTo(const core::Trajectory& trajectory, double t_s,
                                                    double max_gap_s) {
  std::vector<std::vector<Eigen::Vector3d>> lines;
  appendTrackUpTo(trajectory, t_s, max_gap_s, lines);
  return lines;
}

std::vector<std::vector<Eigen::Vector3d>> trackUpTo(const SourceSeries& source, double t_s,
                                                    double max_gap_s) {
  std::vector<std::vector<Eigen::Vector3d>> lines;
  for (const core::Trajectory& stretch : source.tracked) {
    if (stretch.front().t_s > t_s) break;
    appendTrackUpTo(stretch, t_s, max_gap_s, lines);
  }
  return lines;
}

double playbackDuration(const std::vector<RunData>& runs) {
  double duration = 0.0;
  for (const RunData& run : runs) {
    if (!run.truth.empty()) duration = std::max(duration, run.truth.back().t_s - run.t0_s);
  }
  return duration;
}

Eigen::Isometry3d OrbitCamera::worldFromCamera() const {
  const double ce = std::cos(elevation_rad);
  const Eigen::Vector3d forward(ce * std::cos(azimuth_rad), ce * std::sin(azimuth_rad),
                                std::sin(elevation_rad));
  const Eigen::Vector3d up(0.0, 0.0, -1.0);
  const Eigen::Vector3d right = forward.cross(up).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = right;
  T.linear().col(1) = down;
  T.linear().col(2) = forward;
  T.translation() = target - distance_m * forward;
  return T;
}

render::CameraIntrinsics OrbitCamera::intrinsics(int width, int height) const {
  return render::CameraIntrinsics::fromHorizontalFov(std::max(width, 1), std::max(height, 1),
                                                     hfov_rad);
}

void OrbitCamera::rotate(double dx_px, double dy_px) {
  constexpr double kRadPerPx = 0.005;
  azimuth_rad -= dx_px * kRadPerPx;
  // Never straight down (the right vector is undefined there) nor above the horizon.
  elevation_rad = std::clamp(elevation_rad + dy_px * kRadPerPx, 0.05, 1.55);
}

void OrbitCamera::pan(double dx_px, double dy_px, int height_px) {
  // One pixel moves the target by what a pixel covers at the target's distance.
  const double m_per_px = distance_m * std::tan(hfov_rad / 2.0) * 2.0 / std::max(height_px, 1);
  const Eigen::Vector3d north_east_forward(std::cos(azimuth_rad), std::sin(azimuth_rad), 0.0);
  const Eigen::Vector3d right(-std::sin(azimuth_rad), std::cos(azimuth_rad), 0.0);
  target += (-dx_px * right + dy_px * north_east_forward) * m_per_px;
}

void OrbitCamera::zoom(double factor) { distance_m = std::clamp(distance_m * factor, 1.0, 1e6); }

void OrbitCamera::fit(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  target = (lo + hi) / 2.0;
  azimuth_rad = 0.0;
  elevation_rad = std::numbers::pi / 4.0;
  const double extent = std::max((hi - lo).head<2>().norm(), 50.0);
  distance_m = extent / (2.0 * std::tan(hfov_rad / 2.0)) * 1.3;
}

std::optional<Eigen::Vector2d> projectToPixel(const OrbitCamera& camera, int width, int height,
                                              const Eigen::Vector3d& p_world) {
  const Eigen::Vector3d p_cam = camera.worldFromCamera().inverse() * p_world;
  if (p_cam.z() <= 1e-6) return std::nullopt;
  return camera.intrinsics(width, height).project(p_cam);
}

}  // namespace nadir::gui
