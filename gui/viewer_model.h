#pragma once
// nadir-viewer's model, without Qt or OpenGL: where each trajectory is at a playback
// time, the polylines drawn up to it, and the orbit camera that looks at them.
//
// Playback time is seconds since each run's truth start (RunData::t0_s), so runs
// recorded at different clock times play side by side. Positions are world NED, m.

#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "gui/run_data.h"
#include "render/camera_model.h"

namespace nadir::gui {

// A line breaks where samples are further apart than this, as in nadir-plot.
inline constexpr double kViewerMaxGap_s = 1.0;

// A trajectory's position and attitude (body to world NED) at t_s (absolute
// stamp), interpolated by core::interpolate; nothing outside its span or across
// a gap longer than max_gap_s. A source's are those of its TRACKING stretch
// holding t_s.
std::optional<Eigen::Vector3d> positionAt(const core::Trajectory& trajectory, double t_s,
                                          double max_gap_s = kViewerMaxGap_s);
std::optional<Eigen::Vector3d> positionAt(const SourceSeries& source, double t_s,
                                          double max_gap_s = kViewerMaxGap_s);
std::optional<Eigen::Quaterniond> attitudeAt(const core::Trajectory& trajectory, double t_s,
                                             double max_gap_s = kViewerMaxGap_s);

// The polylines from the start up to t_s (absolute stamp), broken where samples
// are more than max_gap_s apart (and, for a source, between TRACKING stretches).
// The last polyline ends at positionAt(t_s) when that exists, so a line grows
// smoothly with time.
std::vector<std::vector<Eigen::Vector3d>> trackUpTo(const core::Trajectory& trajectory, double t_s,
                                                    double max_gap_s = kViewerMaxGap_s);
std::vector<std::vector<Eigen::Vector3d>> trackUpTo(const SourceSeries& source, double t_s,
                                                    double max_gap_s = kViewerMaxGap_s);

// Playback span: 0 to the longest truth's duration, s.
double playbackDuration(const std::vector<RunData>& runs);

// A camera orbiting a target point: it looks along the heading azimuth_rad
// (0 north, pi/2 east), elevation_rad below the horizon, from distance_m away.
struct OrbitCamera {
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  double azimuth_rad = 0.0;
  double elevation_rad = 0.6;
  double distance_m = 500.0;
  double hfov_rad = 1.0;

  // Camera optical frame (x right, y down, z forward) to world NED.
  Eigen::Isometry3d worldFromCamera() const;
  render::CameraIntrinsics intrinsics(int width, int height) const;
  // Drags: rotate by pixels, pan the target by pixels (in the ground plane), zoom
  // by a factor (< 1 closer).
  void rotate(double dx_px, double dy_px);
  void pan(double dx_px, double dy_px, int height_px);
  void zoom(double factor);
  // Looks at the whole box from above at 45 deg, north up.
  void fit(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);
};

// Pixel (x right, y down from the top-left pixel's centre) of a world point, or
// nothing if it is behind the camera.
std::optional<Eigen::Vector2d> projectToPixel(const OrbitCamera& camera, int width, int height,
                                              const Eigen::Vector3d& p_world);

}  // namespace nadir::gui
