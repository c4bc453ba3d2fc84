#pragma once
// A pinhole camera with Brown-Conrady distortion, in OpenCV's conventions:
// optical frame x right, y down, z forward; pixel (0, 0) is the centre of the
// top-left pixel; distortion coefficients k1 k2 p1 p2 k3 as in cv::projectPoints.
// Pure math: no OpenGL here, so the renderer, the calibration and the VO nodes
// all use the same model.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/params.h"

namespace nadir::render {

struct CameraIntrinsics {
  int width = 1280;
  int height = 960;
  double fx = 700.0;
  double fy = 700.0;
  double cx = 639.5;
  double cy = 479.5;
  // k1 k2 p1 p2 k3; all zero = no distortion.
  std::array<double, 5> distortion{};

  // Square pixels, principal point at the image centre, horizontal field of view.
  static CameraIntrinsics fromHorizontalFov(int width, int height, double hfov_rad);
  double horizontalFov_rad() const;
  bool hasDistortion() const;

  // Pixel of a point in the camera optical frame (z > 0), distortion applied.
  Eigen::Vector2d project(const Eigen::Vector3d& p_cam) const;
  // Distorted pixel of a normalised undistorted image point (x/z, y/z).
  Eigen::Vector2d distortNormalised(const Eigen::Vector2d& xy) const;
  // Normalised undistorted point (x/z, y/z) of a distorted pixel, by fixed-point
  // iteration as cv::undistortPoints; nothing if it does not converge.
  std::optional<Eigen::Vector2d> undistortPixel(const Eigen::Vector2d& uv) const;
};

// Vignetting V = 1 / (1 + k r^2)^2, r^2 = x^2 + y^2 in normalised image
// coordinates (x = (u - cx) / fx, y = (v - cy) / fy): the k for which V is
// corner_share at the image corner farthest from the principal point (0 for
// corner_share >= 1: no vignetting). The renderer darkens by it; a VO given
// the lens's calibration divides it out.
double vignettingK(double corner_share, const CameraIntrinsics& intrinsics);
double vignettingAt(double k, double x, double y);

// What a rendering camera adds to the intrinsics: clipping, exposure and noise.
struct CameraParams {
  int width = 1280;
  int height = 960;
  // Horizontal field of view; used when fx is 0.
  double hfov_deg = 84.872;
  // Explicit intrinsics in pixels; fx = 0 means derive them from hfov_deg.
  double fx = 0.0;
  double fy = 0.0;
  double cx = 0.0;
  double cy = 0.0;
  std::vector<double> distortion = {0.0, 0.0, 0.0, 0.0, 0.0};
  double near_m = 0.5;
  double far_m = 20000.0;
  // "gray8" or "rgb8".
  std::string pixel_format = "gray8";
  // Linear gain applied to the rendered radiance (1 = as the imagery).
  double gain = 1.0;
  // Read noise, standard deviation in 8-bit counts; 0 = off.
  double read_noise_counts = 0.0;
  // Shot noise: full-well electrons per count; variance of a pixel = value /
  // this (in counts^2). 0 = off.
  double shot_noise_electrons_per_count = 0.0;
  std::int64_t noise_seed = 1;
  // Sub-imagery texture for low altitudes (off: the imagery alone).
  bool ground_detail = true;
  // Motion blur: each pixel integrates the scene over exposure_s, sampled at
  // motion_blur_samples instants along the camera's path.
  bool motion_blur = false;
  double exposure_s = 0.005;
  int motion_blur_samples = 8;
  // Rolling shutter: row r is exposed readout_s * (r / (height - 1) - 1/2)
  // after the frame's time (the middle row's).
  bool rolling_shutter = false;
  double readout_s = 0.03;
  // With either on, the scene is drawn this much wider on each side, so that
  // what moves into the frame during the exposure or readout is there, px.
  int motion_margin_px = 48;
  // Vignetting: the lens passes vignetting_corner of the centre's light at the
  // image corner, falling off as 1 / (1 + k r^2)^2 (r: distance from the
  // principal point over the focal length; cos^4 for k = 1).
  bool vignetting = false;
  double vignetting_corner = 0.5;
  // Response: counts = 255 (linear / 255)^(1 / response_gamma), after the noise.
  bool response_curve = false;
  double response_gamma = 2.2;
  // Auto-exposure: a gain (on top of gain) that brings the mean of the frames
  // to ae_target_counts, with a first-order lag of ae_time_constant_s in its
  // logarithm, from the frame before.
  bool auto_exposure = false;
  double ae_target_counts = 100.0;
  double ae_time_constant_s = 0.3;
  double ae_gain_min = 0.05;
  double ae_gain_max = 16.0;

  void visit(core::ParamVisitor& v);
  CameraIntrinsics intrinsics() const;
  bool modelsMotion() const { return motion_blur || rolling_shutter; }
  // How far from the frame's time the exposure reaches either way, s.
  double motionHalfSpan_s() const {
    return (rolling_shutter ? 0.5 * readout_s : 0.0) + (motion_blur ? 0.5 * exposure_s : 0.0);
  }
};

}  // namespace nadir::render
