#pragma once
// A software camera for the calibration tests, independent of nadir's OpenGL
// renderer and of the library under test: every output pixel is cut into 4 x 4
// samples; each sample's pixel position is undistorted exactly (Newton, checked
// by the forward model) into a ray, the ray meets the board's plane at a known
// pose, and an analytic checkerboard is read there; the samples are averaged
// (area averaging, as a sensor integrates) and Gaussian noise with a fixed seed
// is added. The true corners are the lens's projection of the board's corners.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <stdexcept>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

namespace nadir::calib::test {

// The true lens: radtan k1 k2 p1 p2 k3 (OpenCV's model) or fisheye k1..k4
// (OpenCV's equidistant model, theta_d = theta (1 + k1 theta^2 + ...)).
struct SyntheticLens {
  int width = 640;
  int height = 480;
  double fx = 520.0;
  double fy = 520.0;
  double cx = 321.3;
  double cy = 238.7;
  bool fisheye = false;
  std::vector<double> distortion = {-0.2, 0.05, 0.0, 0.0, 0.0};

  cv::Matx33d cameraMatrix() const { return {fx, 0, cx, 0, fy, cy, 0, 0, 1}; }
  cv::Size imageSize() const { return {width, height}; }

  // Distorted normalised point (before fx, cx) of an undistorted one (x/z, y/z).
  cv::Vec2d distortNormalised(double x, double y) const {
    if (fisheye) {
      const double r = std::hypot(x, y);
      if (r < 1e-15) return {x, y};
      const double theta = std::atan(r);
      const double t2 = theta * theta;
      const double theta_d =
          theta * (1 + t2 * (distortion[0] +
                             t2 * (distortion[1] + t2 * (distortion[2] + t2 * distortion[3]))));
      return {x * theta_d / r, y * theta_d / r};
    }
    const double k1 = distortion[0], k2 = distortion[1], p1 = distortion[2], p2 = distortion[3],
                 k3 = distortion[4];
    const double r2 = x * x + y * y;
    const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
    return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
            y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
  }

  cv::Point2d project(const cv::Vec3d& p_cam) const {
    const cv::Vec2d d = distortNormalised(p_cam[0] / p_cam[2], p_cam[1] / p_cam[2]);
    return {fx * d[0] + cx, fy * d[1] + cy};
  }

  // Jacobian of distortNormalised: analytic for radtan, central differences
  // for fisheye.
  cv::Matx22d distortionJacobian(double x, double y) const {
    if (fisheye) {
      const double h = 1e-7;
      const cv::Vec2d dx = (distortNormalised(x + h, y) - distortNormalised(x - h, y)) / (2 * h);
      const cv::Vec2d dy = (distortNormalised(x, y + h) - distortNormalised(x, y - h)) / (2 * h);
      return {dx[0], dy[0], dx[1], dy[1]};
    }
    const double k1 = distortion[0], k2 = distortion[1], p1 = distortion[2], p2 = distortion[3],
                 k3 = distortion[4];
    const double r2 = x * x + y * y;
    const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
    const double dradial = k1 + r2 * (2 * k2 + 3 * k3 * r2);  // d radial / d r2
    return {radial + 2 * x * x * dradial + 2 * p1 * y + 6 * p2 * x,
            2 * x * y * dradial + 2 * p1 * x + 2 * p2 * y,
            2 * x * y * dradial + 2 * p1 * x + 2 * p2 * y,
            radial + 2 * y * y * dradial + 6 * p1 * y + 2 * p2 * x};
  }

  // Undistorted normalised point of a pixel: Newton on the forward model from
  // the distorted point; throws if it does not converge to 1e-9 px (the truth
  // must be exact, not approximately so).
  cv::Vec2d undistortPixel(double u, double v) const {
    const cv::Vec2d target((u - cx) / fx, (v - cy) / fy);
    cv::Vec2d xy = target;
    for (int i = 0; i < 50; ++i) {
      const cv::Vec2d f = distortNormalised(xy[0], xy[1]) - target;
      if (std::abs(f[0]) * fx < 1e-10 && std::abs(f[1]) * fy < 1e-10) return xy;
      xy -= distortionJacobian(xy[0], xy[1]).inv() * f;
    }
    const cv::Vec2d f = distortNormalised(xy[0], xy[1]) - target;
    if (std::abs(f[0]) * fx > 1e-9 || std::abs(f[1]) * fy > 1e-9)
      throw std::runtime_error("synthetic lens: undistortion did not converge");
    return xy;
  }

  // True when the board outline (board frame points) lies inside the image
  // with border_px to spare and in front of the camera.
  bool fits(const std::array<cv::Vec3d, 4>& outline, const cv::Vec3d& rvec, const cv::Vec3d& tvec,
            double border_px) const {
    cv::Matx33d R;
    cv::Rodrigues(rvec, R);
    // The outline's edges, sampled: distortion bends them.
    for (int e = 0; e < 4; ++e) {
      for (int s = 0; s <= 20; ++s) {
        const cv::Vec3d p = outline[e] + (outline[(e + 1) % 4] - outline[e]) * (s / 20.0);
        const cv::Vec3d p_cam = R * p + tvec;
        if (p_cam[2] <= 0.05) return false;
        const cv::Point2d uv = project(p_cam);
        if (uv.x < border_px || uv.y < border_px || uv.x > width - 1 - border_px ||
            uv.y > height - 1 - border_px)
          return false;
      }
    }
    return true;
  }
};

// Pose of the board in the camera: p_cam = R(rvec) p_board + tvec. The board
// frame has its origin at the first inner corner, x along a row of corners, y
// down the columns, z = 0 on the board.
struct BoardPose {
  cv::Vec3d rvec;
  cv::Vec3d tvec;
};

struct SyntheticBoard {
  int inner_cols = 9;
  int inner_rows = 6;
  double square_m = 0.03;
  // White margin around the squares, in squares (findChessboardCornersSB wants one).
  double margin_squares = 1.0;
  double black = 40.0;
  double white = 210.0;
  double background = 110.0;

  std::vector<cv::Point3f> corners_board() const {
    std::vector<cv::Point3f> points;
    for (int r = 0; r < inner_rows; ++r)
      for (int c = 0; c < inner_cols; ++c)
        points.emplace_back(static_cast<float>(c * square_m), static_cast<float>(r * square_m),
                            0.f);
    return points;
  }
  // The outline of the board with its margin, in the board frame.
  std::array<cv::Vec3d, 4> outline_board() const {
    const double lo = -(1 + margin_squares) * square_m;
    const double hx = (inner_cols + margin_squares) * square_m;
    const double hy = (inner_rows + margin_squares) * square_m;
    return {cv::Vec3d(lo, lo, 0), cv::Vec3d(hx, lo, 0), cv::Vec3d(hx, hy, 0), cv::Vec3d(lo, hy, 0)};
  }
  cv::Vec3d centre_board() const {
    return {0.5 * (inner_cols - 1) * square_m, 0.5 * (inner_rows - 1) * square_m, 0};
  }
  // Intensity at a board point: squares (cols + 1) x (rows + 1), the square
  // touching the first corner from the top-left black, a white margin around.
  double intensity(double x, double y) const {
    const double ix = std::floor(x / square_m), iy = std::floor(y / square_m);
    if (ix < -1 || iy < -1 || ix > inner_cols - 1 || iy > inner_rows - 1) {
      const double lo = -(1 + margin_squares), hx = inner_cols + margin_squares,
                   hy = inner_rows + margin_squares;
      const double sx = x / square_m, sy = y / square_m;
      return (sx >= lo && sy >= lo && sx < hx && sy < hy) ? white : background;
    }
    return (static_cast<long>(ix + iy) % 2 == 0) ? black : white;
  }
};

class SyntheticCamera {
 public:
  static constexpr int kSamples = 4;  // per pixel side

  SyntheticCamera(const SyntheticLens& lens, const SyntheticBoard& board)
      : lens_(lens), board_(board) {
    const int w = lens.width * kSamples, h = lens.height * kSamples;
    rays_.resize(static_cast<std::size_t>(w) * h);
    for (int j = 0; j < h; ++j) {
      for (int i = 0; i < w; ++i) {
        // Pixel (0, 0)'s centre is at (0, 0): samples at -3/8, -1/8, 1/8, 3/8.
        const double u = (i + 0.5) / kSamples - 0.5, v = (j + 0.5) / kSamples - 0.5;
        const cv::Vec2d xy = lens.undistortPixel(u, v);
        rays_[static_cast<std::size_t>(j) * w + i] =
            cv::Vec2f(static_cast<float>(xy[0]), static_cast<float>(xy[1]));
      }
    }
  }

  const SyntheticLens& lens() const { return lens_; }
  const SyntheticBoard& board() const { return board_; }

  // 8-bit grey image of the board at the pose, noise with standard deviation
  // noise_counts from cv::RNG(seed).
  cv::Mat render(const BoardPose& pose, double noise_counts, std::uint64_t seed) const {
    cv::Matx33d R;
    cv::Rodrigues(pose.rvec, R);
    const cv::Vec3d n(R(0, 2), R(1, 2), R(2, 2));  // plane normal in the camera frame
    const cv::Vec3d ex(R(0, 0), R(1, 0), R(2, 0)), ey(R(0, 1), R(1, 1), R(2, 1));
    const cv::Vec3d t = pose.tvec;
    const double nt = n.dot(t), ext = ex.dot(t), eyt = ey.dot(t);
    const int w = lens_.width * kSamples;
    cv::Mat out(lens_.height, lens_.width, CV_64F);
    auto sample = [&](const cv::Vec2f& ray) {
      const cv::Vec3d d(ray[0], ray[1], 1.0);
      const double nd = n.dot(d);
      const double lambda = nt / nd;
      if (!(lambda > 0) || std::abs(nd) < 1e-12) return board_.background;
      // Board coordinates of the hit point: R^T (lambda d - t).
      return board_.intensity(lambda * ex.dot(d) - ext, lambda * ey.dot(d) - eyt);
    };
    for (int v = 0; v < lens_.height; ++v) {
      for (int u = 0; u < lens_.width; ++u) {
        const cv::Vec2f* row0 = &rays_[static_cast<std::size_t>(v * kSamples) * w + u * kSamples];
        const cv::Vec2f* row3 = row0 + static_cast<std::size_t>(kSamples - 1) * w;
        // All 16 samples lie inside the hull of the 4 outer ones: when those 4
        // agree, no edge and no square's corner crosses the pixel (squares
        // larger than a pixel), and the pixel is uniform.
        const double a = sample(row0[0]), b = sample(row0[kSamples - 1]);
        const double c = sample(row3[0]), d = sample(row3[kSamples - 1]);
        if (a == b && a == c && a == d) {
          out.at<double>(v, u) = a;
          continue;
        }
        double sum = 0.0;
        for (int sj = 0; sj < kSamples; ++sj) {
          const cv::Vec2f* row = row0 + static_cast<std::size_t>(sj) * w;
          for (int si = 0; si < kSamples; ++si) sum += sample(row[si]);
        }
        out.at<double>(v, u) = sum / (kSamples * kSamples);
      }
    }
    if (noise_counts > 0) {
      cv::Mat noise(out.size(), CV_64F);
      cv::RNG rng(seed);
      rng.fill(noise, cv::RNG::NORMAL, 0.0, noise_counts);
      out += noise;
    }
    cv::Mat image;
    out.convertTo(image, CV_8U);  // rounds and saturates
    return image;
  }

  std::vector<cv::Point2f> trueCorners(const BoardPose& pose) const {
    cv::Matx33d R;
    cv::Rodrigues(pose.rvec, R);
    std::vector<cv::Point2f> pixels;
    for (const cv::Point3f& p : board_.corners_board()) {
      const cv::Vec3d p_cam = R * cv::Vec3d(p.x, p.y, p.z) + pose.tvec;
      const cv::Point2d uv = lens_.project(p_cam);
      pixels.emplace_back(static_cast<float>(uv.x), static_cast<float>(uv.y));
    }
    return pixels;
  }

 private:
  SyntheticLens lens_;
  SyntheticBoard board_;
  std::vector<cv::Vec2f> rays_;  // undistorted (x/z, y/z) of every sample
};

// One view as a person holds the board: its centre at image fraction (u, v)
// at distance_m, tilted about its x and y axes, turned about the optical axis.
struct ViewSpec {
  double u;
  double v;
  double distance_m;
  double tilt_x_deg;
  double tilt_y_deg;
  double roll_deg;
};

// 20 views covering the image: centres over a 3 x 3 grid and beyond, near and
// far, tilted up to 40 deg. Fixed table, no random numbers.
inline std::vector<ViewSpec> coveringViewSpecs() {
  return {
      {0.50, 0.50, 0.40, 0, 0, 0},      {0.25, 0.25, 0.45, 20, -25, 5},
      {0.50, 0.25, 0.45, 30, 0, -8},    {0.75, 0.25, 0.45, 20, 25, 10},
      {0.25, 0.50, 0.45, 0, -35, -5},   {0.75, 0.50, 0.45, 0, 35, 5},
      {0.25, 0.75, 0.45, -20, -25, 8},  {0.50, 0.75, 0.45, -30, 0, 3},
      {0.75, 0.75, 0.45, -20, 25, -10}, {0.50, 0.50, 0.35, 15, 15, 30},
      {0.35, 0.40, 0.40, -40, 10, -20}, {0.65, 0.60, 0.40, 40, -10, 20},
      {0.30, 0.65, 0.40, 10, 40, 15},   {0.70, 0.35, 0.40, -10, -40, -15},
      {0.20, 0.20, 0.60, 10, 10, 0},    {0.80, 0.80, 0.60, -10, -10, 0},
      {0.80, 0.20, 0.60, 10, -10, 45},  {0.20, 0.80, 0.60, -10, 10, -45},
      {0.50, 0.50, 0.50, 25, -30, 90},  {0.45, 0.55, 0.40, -25, 30, -60},
  };
}

// The pose of a view: the board's centre on the ray through pixel (u W, v H);
// pushed back 4 % at a time until the whole board fits with 6 px to spare.
inline BoardPose poseOf(const SyntheticLens& lens, const SyntheticBoard& board,
                        const ViewSpec& spec) {
  constexpr double kDeg = std::numbers::pi / 180.0;
  const cv::Vec2d xy = lens.undistortPixel(spec.u * (lens.width - 1), spec.v * (lens.height - 1));
  cv::Vec3d ray(xy[0], xy[1], 1.0);
  ray /= cv::norm(ray);
  cv::Matx33d Rx, Ry, Rz;
  cv::Rodrigues(cv::Vec3d(spec.tilt_x_deg * kDeg, 0, 0), Rx);
  cv::Rodrigues(cv::Vec3d(0, spec.tilt_y_deg * kDeg, 0), Ry);
  cv::Rodrigues(cv::Vec3d(0, 0, spec.roll_deg * kDeg), Rz);
  const cv::Matx33d R = Rz * Rx * Ry;
  BoardPose pose;
  cv::Rodrigues(R, pose.rvec);
  for (double d = spec.distance_m; d < 20 * spec.distance_m; d *= 1.04) {
    pose.tvec = ray * d - R * board.centre_board();
    if (lens.fits(board.outline_board(), pose.rvec, pose.tvec, 6.0)) return pose;
  }
  throw std::runtime_error("synthetic view does not fit in the image");
}

inline std::vector<BoardPose> coveringPoses(const SyntheticLens& lens,
                                            const SyntheticBoard& board) {
  std::vector<BoardPose> poses;
  for (const ViewSpec& spec : coveringViewSpecs()) poses.push_back(poseOf(lens, board, spec));
  return poses;
}

}  // namespace nadir::calib::test
