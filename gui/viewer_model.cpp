#include "gui/viewer_model.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/frames.h"

namespace nadir::gui {
namespace {

bool hasPose(const PoseSeries& s, std::size_t i) {
  return std::isfinite(s.x_m[i]) && std::isfinite(s.y_m[i]) && std::isfinite(s.z_m[i]);
}

Eigen::Vector3d at(const PoseSeries& s, std::size_t i) { return {s.x_m[i], s.y_m[i], s.z_m[i]}; }

Eigen::Quaterniond attitudeOf(const PoseSeries& s, std::size_t i) {
  constexpr double kRadPerDeg = std::numbers::pi / 180.0;
  return core::quaternionFromRpy(
      {s.roll_deg[i] * kRadPerDeg, s.pitch_deg[i] * kRadPerDeg, s.yaw_deg[i] * kRadPerDeg});
}

// The samples around t_s and the fraction of the way from the first to the second
// (the same sample twice at the series' last stamp), under positionAt's conditions.
struct Bracket {
  std::size_t i0 = 0;
  std::size_t i1 = 0;
  double a = 0.0;
};

std::optional<Bracket> bracket(const PoseSeries& series, double t_s, double max_gap_s) {
  const auto& t = series.t_s;
  if (t.empty() || t_s < t.front() || t_s > t.back()) return std::nullopt;
  const auto upper = std::upper_bound(t.begin(), t.end(), t_s);
  if (upper == t.end()) {
    const std::size_t last = t.size() - 1;
    if (!hasPose(series, last)) return std::nullopt;
    return Bracket{last, last, 0.0};
  }
  const auto i1 = static_cast<std::size_t>(upper - t.begin());
  const std::size_t i0 = i1 - 1;
  if (!hasPose(series, i0) || !hasPose(series, i1) || t[i1] - t[i0] > max_gap_s) {
    return std::nullopt;
  }
  return Bracket{i0, i1, (t_s - t[i0]) / (t[i1] - t[i0])};
}

}  // namespace

std::optional<Eigen::Vector3d> positionAt(const PoseSeries& series, double t_s, double max_gap_s) {
  const std::optional<Bracket> b = bracket(series, t_s, max_gap_s);
  if (!b) return std::nullopt;
  return (1.0 - b->a) * at(series, b->i0) + b->a * at(series, b->i1);
}

std::optional<Eigen::Quaterniond> attitudeAt(const PoseSeries& series, double t_s,
                                             double max_gap_s) {
  const std::optional<Bracket> b = bracket(series, t_s, max_gap_s);
  if (!b) return std::nullopt;
  return attitudeOf(series, b->i0).slerp(b->a, attitudeOf(series, b->i1));
}

std::vector<std::vector<Eigen::Vector3d>> trackUpTo(const PoseSeries& series, double t_s,
                                                    double max_gap_s) {
  std::vector<std::vector<Eigen::Vector3d>> lines;
  std::vector<Eigen::Vector3d> line;
  double last_t = 0.0;
  for (std::size_t i = 0; i < series.size() && series.t_s[i] <= t_s; ++i) {
    const bool broken =
        !hasPose(series, i) || (!line.empty() && series.t_s[i] - last_t > max_gap_s);
    if (broken) {
      if (!line.empty()) lines.push_back(std::move(line));
      line.clear();
    }
    if (hasPose(series, i)) {
      line.push_back(at(series, i));
      last_t = series.t_s[i];
    }
  }
  if (const auto now = positionAt(series, t_s, max_gap_s); now && !line.empty()) {
    if ((*now - line.back()).norm() > 0.0) line.push_back(*now);
  }
  if (!line.empty()) lines.push_back(std::move(line));
  return lines;
}

double playbackDuration(const std::vector<RunData>& runs) {
  double duration = 0.0;
  for (const RunData& run : runs) {
    if (!run.truth.t_s.empty()) duration = std::max(duration, run.truth.t_s.back() - run.t0_s);
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
