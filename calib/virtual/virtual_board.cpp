#include "calib/virtual/virtual_board.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

#include "core/frames.h"
#include "render/egl_context.h"
#include "render/terrain_renderer.h"
#include "terrain/tiles.h"

namespace nadir::calib {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// Uniform in [0, 1) from the generator's raw output (the same on every
// standard library, unlike std::uniform_real_distribution).
double uniform01(std::mt19937& rng) { return static_cast<double>(rng() >> 8) * 0x1.0p-24; }

// The board's outline with its margin, sampled along its edges (a barrel lens
// bends the edges outwards between the corners), world frame.
std::vector<Eigen::Vector3d> outline_world(const terrain::CheckerboardParams& board) {
  const double half_n = 0.5 * (board.inner_rows + 3) * board.square_m;
  const double half_e = 0.5 * (board.inner_cols + 3) * board.square_m;
  const std::array<Eigen::Vector3d, 4> corners{
      Eigen::Vector3d(-half_n, -half_e, 0.0), Eigen::Vector3d(-half_n, half_e, 0.0),
      Eigen::Vector3d(half_n, half_e, 0.0), Eigen::Vector3d(half_n, -half_e, 0.0)};
  constexpr int kPerEdge = 8;
  std::vector<Eigen::Vector3d> points;
  for (std::size_t k = 0; k < corners.size(); ++k) {
    const Eigen::Vector3d& a = corners[k];
    const Eigen::Vector3d& b = corners[(k + 1) % corners.size()];
    for (int s = 0; s < kPerEdge; ++s) points.push_back(a + (b - a) * (s / double(kPerEdge)));
  }
  return points;
}

// Largest normalised radius the image reaches (at its farthest corner): a
// point beyond it is outside the image even where the distortion polynomial
// folds it back in.
double maxNormalisedRadius(const render::CameraIntrinsics& k) {
  double r_max = 0.0;
  const std::array<Eigen::Vector2d, 4> image_corners{
      Eigen::Vector2d(0, 0), Eigen::Vector2d(k.width - 1, 0), Eigen::Vector2d(0, k.height - 1),
      Eigen::Vector2d(k.width - 1, k.height - 1)};
  for (const Eigen::Vector2d& uv : image_corners) {
    const auto xy = k.undistortPixel(uv);
    if (!xy) throw std::invalid_argument("virtual board: the lens's corners do not undistort");
    r_max = std::max(r_max, xy->norm());
  }
  return r_max;
}

bool inView(const std::vector<Eigen::Vector3d>& outline, const Eigen::Isometry3d& T_world_cam,
            const render::CameraIntrinsics& k, double r_max, double border_px) {
  const Eigen::Isometry3d T_cam_world = T_world_cam.inverse();
  for (const Eigen::Vector3d& p_world : outline) {
    const Eigen::Vector3d p_cam = T_cam_world * p_world;
    if (p_cam.z() <= 0.0) return false;
    if (p_cam.head<2>().norm() / p_cam.z() > r_max) return false;
    const Eigen::Vector2d uv = k.project(p_cam);
    if (uv.x() < border_px || uv.y() < border_px || uv.x() > k.width - 1 - border_px ||
        uv.y() > k.height - 1 - border_px) {
      return false;
    }
  }
  return true;
}

}  // namespace

void VirtualViewParams::visit(core::ParamVisitor& v) {
  v.field("views", &views, {.doc = "poses the board is seen from", .min = 1, .max = 100000});
  v.field("max_fill", &max_fill,
          {.doc = "board width over image width, nearest views", .min = 0.05, .max = 1.0});
  v.field("min_fill", &min_fill,
          {.doc = "board width over image width, farthest views", .min = 0.05, .max = 1.0});
  v.field("max_tilt_deg", &max_tilt_deg,
          {.doc = "largest angle of the board to the image plane, deg", .min = 0, .max = 70});
  v.field("max_roll_deg", &max_roll_deg,
          {.doc = "largest turn of the board about the optical axis, deg", .min = 0, .max = 180});
  v.field("border_px", &border_px,
          {.doc = "the whole board stays this far inside the image, px", .min = 0, .max = 1000});
  v.field("seed", &seed, {.doc = "seed of the poses"});
}

std::vector<Eigen::Isometry3d> coveringPoses(const terrain::CheckerboardParams& board,
                                             const render::CameraIntrinsics& k,
                                             const VirtualViewParams& params) {
  VirtualViewParams checked = params;
  core::validateParams([&checked](core::ParamVisitor& v) { checked.visit(v); },
                       "virtual board views");
  if (params.min_fill > params.max_fill) {
    throw std::invalid_argument("virtual board: min_fill " + std::to_string(params.min_fill) +
                                " is above max_fill " + std::to_string(params.max_fill));
  }
  const std::vector<Eigen::Vector3d> outline = outline_world(board);
  const double board_width_m = (board.inner_cols + 3) * board.square_m;
  const double r_max = maxNormalisedRadius(k);
  const Eigen::Matrix3d R_world_down = core::rotationBodyFromDownCamera();
  const Eigen::Vector2d centre_px(0.5 * (k.width - 1), 0.5 * (k.height - 1));
  std::mt19937 rng(static_cast<std::uint32_t>(params.seed));

  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < params.views; ++i) {
    // Near and far spread evenly (golden-ratio steps), the board's centre over
    // a 3 x 3 grid of the image with some jitter, tilt towards any side.
    const double spread = std::fmod(0.5 + i * 0.6180339887498949, 1.0);
    double fill = params.max_fill - (params.max_fill - params.min_fill) * spread;
    const int cell = i % 9;
    const Eigen::Vector2d target_px(
        k.width * ((cell % 3) * 0.3 + 0.2 + 0.1 * (uniform01(rng) - 0.5)),
        k.height * ((cell / 3) * 0.3 + 0.2 + 0.1 * (uniform01(rng) - 0.5)));
    const double tilt_rad = params.max_tilt_deg * kDeg * std::sqrt(uniform01(rng));
    const double tilt_axis_rad = 2.0 * std::numbers::pi * uniform01(rng);
    const double roll_rad = params.max_roll_deg * kDeg * (2.0 * uniform01(rng) - 1.0);
    const Eigen::Matrix3d R_world_cam =
        R_world_down * Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
        Eigen::AngleAxisd(tilt_rad,
                          Eigen::Vector3d(std::cos(tilt_axis_rad), std::sin(tilt_axis_rad), 0.0))
            .toRotationMatrix();

    // Where the board does not fit, bring it towards the image's centre, then
    // make it smaller.
    bool placed = false;
    for (int shrink = 0; shrink < 20 && !placed; ++shrink, fill *= 0.92) {
      const double depth_m = k.fx * board_width_m / (fill * k.width);
      for (double towards = 1.0; towards >= -1e-9 && !placed; towards -= 0.125) {
        const Eigen::Vector2d uv = centre_px + towards * (target_px - centre_px);
        const auto xy = k.undistortPixel(uv);
        if (!xy) continue;
        Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
        T_world_cam.linear() = R_world_cam;
        T_world_cam.translation() =
            -(R_world_cam * (depth_m * Eigen::Vector3d(xy->x(), xy->y(), 1.0)));
        if (inView(outline, T_world_cam, k, r_max, params.border_px)) {
          poses.push_back(T_world_cam);
          placed = true;
        }
      }
    }
    if (!placed) {
      throw std::invalid_argument(
          "virtual board: view " + std::to_string(i) + " cannot hold the whole " +
          std::to_string(board.inner_cols) + "x" + std::to_string(board.inner_rows) +
          " board in the image; lower views.max_tilt_deg or views.min_fill");
    }
  }
  return poses;
}

std::vector<Eigen::Vector3d> boardCorners_world(const terrain::CheckerboardWorld& world) {
  std::vector<Eigen::Vector3d> corners;
  for (int row = 0; row < world.board().inner_rows; ++row) {
    for (int col = 0; col < world.board().inner_cols; ++col) {
      corners.emplace_back(world.cornerNorth_m(row), world.cornerEast_m(col),
                           -world.groundUp_m(0.0, 0.0));
    }
  }
  return corners;
}

struct VirtualCheckerboard::Gl {
  render::HeadlessGlContext context;
  std::shared_ptr<terrain::TileTree> tiles;
  std::unique_ptr<render::TerrainRenderer> terrain;
  std::unique_ptr<render::CameraRenderer> camera;
};

VirtualCheckerboard::VirtualCheckerboard(const terrain::CheckerboardParams& board,
                                         const render::CameraParams& camera,
                                         const VirtualViewParams& views)
    : world_(std::make_shared<terrain::CheckerboardWorld>(board)),
      poses_(coveringPoses(board, camera.intrinsics(), views)),
      gl_(std::make_unique<Gl>()) {
  double nearest_m = 1e300;
  double farthest_m = 0.0;
  for (const Eigen::Isometry3d& T_world_cam : poses_) {
    const double d = T_world_cam.translation().norm();
    nearest_m = std::min(nearest_m, d);
    farthest_m = std::max(farthest_m, d);
  }
  render::CameraParams lens = camera;
  // Tilted views see the ground towards the horizon: a far plane well past
  // the board; the near plane well inside the nearest board point.
  lens.near_m = 0.1 * nearest_m * std::cos(views.max_tilt_deg * kDeg);
  lens.far_m = 1000.0 * farthest_m;
  lens.ground_detail = false;
  // Tile textures of a power-of-two side with their border texels: the
  // default 512 + 2 makes a mip chain (514, 257, 128, ...) whose odd levels
  // are resampled, which moved the corners of minified boards outwards by up
  // to 0.12 px and biased fx by -0.07 % (docs/calibration.md).
  terrain::TileParams tile_params;
  tile_params.texture_px = 510;
  gl_->tiles = std::make_shared<terrain::TileTree>(world_, tile_params);
  gl_->terrain =
      std::make_unique<render::TerrainRenderer>(gl_->tiles, render::TerrainRendererParams{});
  gl_->camera = std::make_unique<render::CameraRenderer>(*gl_->terrain, lens);
}

VirtualCheckerboard::~VirtualCheckerboard() = default;

render::RenderedImage VirtualCheckerboard::render(int i) {
  if (i < 0 || i >= size()) {
    throw std::out_of_range("virtual board: view " + std::to_string(i) + " of " +
                            std::to_string(size()));
  }
  gl_->context.makeCurrent();
  return gl_->camera->render(poses_[static_cast<std::size_t>(i)],
                             static_cast<std::int64_t>(i) * 100000);
}

const render::CameraIntrinsics& VirtualCheckerboard::intrinsics() const {
  return gl_->camera->intrinsics();
}

}  // namespace nadir::calib
