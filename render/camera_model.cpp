#include "render/camera_model.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace nadir::render {

CameraIntrinsics CameraIntrinsics::fromHorizontalFov(int width, int height, double hfov_rad) {
  CameraIntrinsics k;
  k.width = width;
  k.height = height;
  k.fx = 0.5 * width / std::tan(0.5 * hfov_rad);
  k.fy = k.fx;
  k.cx = 0.5 * (width - 1);
  k.cy = 0.5 * (height - 1);
  return k;
}

double CameraIntrinsics::horizontalFov_rad() const { return 2.0 * std::atan(0.5 * width / fx); }

bool CameraIntrinsics::hasDistortion() const {
  for (double c : distortion) {
    if (c != 0.0) return true;
  }
  return false;
}

Eigen::Vector2d CameraIntrinsics::distortNormalised(const Eigen::Vector2d& xy) const {
  const double x = xy.x(), y = xy.y();
  const auto [k1, k2, p1, p2, k3] = distortion;
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x);
  const double yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y;
  return {fx * xd + cx, fy * yd + cy};
}

Eigen::Vector2d CameraIntrinsics::project(const Eigen::Vector3d& p_cam) const {
  return distortNormalised({p_cam.x() / p_cam.z(), p_cam.y() / p_cam.z()});
}

std::optional<Eigen::Vector2d> CameraIntrinsics::undistortPixel(const Eigen::Vector2d& uv) const {
  const Eigen::Vector2d xd((uv.x() - cx) / fx, (uv.y() - cy) / fy);
  if (!hasDistortion()) return xd;
  const auto [k1, k2, p1, p2, k3] = distortion;
  Eigen::Vector2d xy = xd;
  for (int i = 0; i < 100; ++i) {
    const double x = xy.x(), y = xy.y();
    const double r2 = x * x + y * y;
    const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
    const double dx = 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x);
    const double dy = p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y;
    const Eigen::Vector2d next((xd.x() - dx) / radial, (xd.y() - dy) / radial);
    const double step = (next - xy).norm();
    xy = next;
    if (step < 1e-12) break;
  }
  const Eigen::Vector2d back = distortNormalised(xy);
  if (!std::isfinite(back.x()) || (back - uv).norm() > 1e-6) return std::nullopt;
  return xy;
}

void CameraParams::visit(core::ParamVisitor& v) {
  v.field("width", &width, {.doc = "image width, px", .min = 16, .max = 8192});
  v.field("height", &height, {.doc = "image height, px", .min = 16, .max = 8192});
  v.field("hfov_deg", &hfov_deg,
          {.doc = "horizontal field of view, deg (used when fx = 0)", .min = 1, .max = 170});
  v.field("fx", &fx, {.doc = "focal length x, px; 0 = from hfov_deg", .min = 0, .max = 1e6});
  v.field("fy", &fy, {.doc = "focal length y, px; 0 = fx", .min = 0, .max = 1e6});
  v.field("cx", &cx,
          {.doc = "principal point x, px; cx = cy = 0: image centre", .min = -1e5, .max = 1e5});
  v.field("cy", &cy,
          {.doc = "principal point y, px; cx = cy = 0: image centre", .min = -1e5, .max = 1e5});
  v.field("distortion", &distortion,
          {.doc = "Brown-Conrady k1 k2 p1 p2 k3 (OpenCV order)",
           .min = -10,
           .max = 10,
           .list_size = 5});
  v.field("near_m", &near_m, {.doc = "near clipping distance, m", .min = 1e-3, .max = 1e4});
  v.field("far_m", &far_m, {.doc = "far clipping distance, m", .min = 1, .max = 1e6});
  v.field("pixel_format", &pixel_format, {.doc = "gray8 or rgb8", .choices = {"gray8", "rgb8"}});
  v.field("gain", &gain, {.doc = "linear gain on the rendered radiance", .min = 0, .max = 100});
  v.field("read_noise_counts", &read_noise_counts,
          {.doc = "Gaussian read noise, std dev in 8-bit counts; 0 = off", .min = 0, .max = 255});
  v.field("shot_noise_electrons_per_count", &shot_noise_electrons_per_count,
          {.doc = "electrons per count for shot noise; 0 = off", .min = 0, .max = 1e6});
  v.field("noise_seed", &noise_seed, {.doc = "seed of the per-frame noise"});
  v.field("ground_detail", &ground_detail,
          {.doc = "add texture finer than the imagery for low altitudes"});
  v.field("motion_blur", &motion_blur,
          {.doc = "integrate the scene over the exposure along the camera's path"});
  v.field("exposure_s", &exposure_s, {.doc = "exposure time, s", .min = 0, .max = 1});
  v.field("motion_blur_samples", &motion_blur_samples,
          {.doc = "instants the exposure is sampled at", .min = 1, .max = 64});
  v.field("rolling_shutter", &rolling_shutter,
          {.doc = "expose the rows one after the other over readout_s"});
  v.field("readout_s", &readout_s,
          {.doc = "time from the first row to the last, s", .min = 0, .max = 1});
  v.field("vignetting", &vignetting, {.doc = "darken towards the corners as a lens does"});
  v.field("vignetting_corner", &vignetting_corner,
          {.doc = "share of the centre's light at the image corner", .min = 0.01, .max = 1});
  v.field("response_curve", &response_curve, {.doc = "apply a gamma response after the noise"});
  v.field("response_gamma", &response_gamma,
          {.doc = "counts = 255 (linear / 255)^(1 / gamma)", .min = 0.1, .max = 10});
  v.field("auto_exposure", &auto_exposure,
          {.doc = "steer a gain so that the frames' mean reaches ae_target_counts"});
  v.field("ae_target_counts", &ae_target_counts,
          {.doc = "mean the auto-exposure aims at, counts", .min = 1, .max = 254});
  v.field("ae_time_constant_s", &ae_time_constant_s,
          {.doc = "auto-exposure time constant, s", .min = 0.001, .max = 100});
  v.field("ae_gain_min", &ae_gain_min,
          {.doc = "least auto-exposure gain", .min = 1e-4, .max = 1e4});
  v.field("ae_gain_max", &ae_gain_max,
          {.doc = "largest auto-exposure gain", .min = 1e-4, .max = 1e4});
  v.field("motion_margin_px", &motion_margin_px,
          {.doc = "scene drawn this much wider per side for blur and rolling shutter, px",
           .min = 0,
           .max = 1024});
}

double vignettingK(double corner_share, const CameraIntrinsics& intrinsics) {
  if (!(corner_share < 1.0)) return 0.0;
  const double x = std::max(intrinsics.cx, intrinsics.width - 1 - intrinsics.cx) / intrinsics.fx;
  const double y = std::max(intrinsics.cy, intrinsics.height - 1 - intrinsics.cy) / intrinsics.fy;
  return (1.0 / std::sqrt(corner_share) - 1.0) / (x * x + y * y);
}

double vignettingAt(double k, double x, double y) {
  const double v = 1.0 + k * (x * x + y * y);
  return 1.0 / (v * v);
}

CameraIntrinsics CameraParams::intrinsics() const {
  CameraIntrinsics k =
      CameraIntrinsics::fromHorizontalFov(width, height, hfov_deg * std::numbers::pi / 180.0);
  if (fx > 0.0) {
    k.fx = fx;
    k.fy = fy > 0.0 ? fy : fx;
    if (cx != 0.0 || cy != 0.0) {
      k.cx = cx;
      k.cy = cy;
    }
  }
  for (std::size_t i = 0; i < k.distortion.size(); ++i) k.distortion[i] = distortion[i];
  return k;
}

}  // namespace nadir::render
