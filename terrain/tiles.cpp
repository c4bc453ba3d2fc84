#include "terrain/tiles.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace nadir::terrain {

TileId TileId::child(int quadrant) const {
  return {level + 1, 2 * ix + (quadrant & 1), 2 * iy + ((quadrant >> 1) & 1)};
}

std::uint64_t TileId::key() const {
  return (static_cast<std::uint64_t>(level) << 56) | (static_cast<std::uint64_t>(ix) << 28) |
         static_cast<std::uint64_t>(iy);
}

Eigen::Vector3d TileGeometry::boxMin() const {
  return {square.north_min_m, square.east_min_m, -static_cast<double>(max_up_m)};
}

Eigen::Vector3d TileGeometry::boxMax() const {
  return {square.north_min_m + square.size_m, square.east_min_m + square.size_m,
          -static_cast<double>(min_up_m)};
}

double TileGeometry::distanceFrom_m(const Eigen::Vector3d& p_ned) const {
  return (p_ned.cwiseMax(boxMin()).cwiseMin(boxMax()) - p_ned).norm();
}

void TileParams::visit(core::ParamVisitor& v) {
  v.field("mesh_quads", &mesh_quads, {.doc = "mesh quads along a tile edge", .min = 1, .max = 256});
  v.field("texture_px", &texture_px,
          {.doc = "texture pixels along a tile edge", .min = 16, .max = 4096});
  v.field("max_geometric_error_px", &max_geometric_error_px,
          {.doc = "refine while the mesh error seen from the camera exceeds this, px",
           .min = 0.01,
           .max = 1000});
  v.field(
      "max_texel_px", &max_texel_px,
      {.doc = "refine while a texel covers more image pixels than this", .min = 0.05, .max = 100});
  v.field("geometry_cache_mib", &geometry_cache_mib,
          {.doc = "memory for cached tile meshes, MiB", .min = 1, .max = 65536});
}

TileTree::TileTree(std::shared_ptr<const World> world, const TileParams& params)
    : world_(std::move(world)), params_(params) {
  core::validateParams([this](core::ParamVisitor& v) { params_.visit(v); }, "tile parameters");
  const WorldExtent extent = world_->extent();
  const double size_m =
      std::max(extent.north_max_m - extent.north_min_m, extent.east_max_m - extent.east_min_m);
  root_ = {0.5 * (extent.north_min_m + extent.north_max_m) - 0.5 * size_m,
           0.5 * (extent.east_min_m + extent.east_max_m) - 0.5 * size_m, size_m};
  // Finest level: where a texel reaches the world's imagery resolution.
  const double coarsest_texel_m = size_m / params_.texture_px;
  const double finest_texel_m = std::max(world_->imageryResolution_m(), 1e-3);
  max_level_ =
      std::clamp(static_cast<int>(std::ceil(std::log2(coarsest_texel_m / finest_texel_m))), 0, 24);
}

GroundSquare TileTree::squareOf(const TileId& id) const {
  const double size_m = root_.size_m / static_cast<double>(1 << id.level);
  return {root_.north_min_m + id.iy * size_m, root_.east_min_m + id.ix * size_m, size_m};
}

std::shared_ptr<TileGeometry> TileTree::computeGeometry(const TileId& id) const {
  auto tile = std::make_shared<TileGeometry>();
  tile->id = id;
  tile->square = squareOf(id);
  const int quads = params_.mesh_quads;
  const int n = quads + 1;
  tile->vertices_per_edge = n;
  tile->height_up_m.resize(static_cast<std::size_t>(n) * n);
  const double step_m = tile->square.size_m / quads;
  // Heights on the doubled grid: even indices are mesh vertices, odd ones the
  // points between them where the mesh error is measured.
  const int fine = 2 * quads + 1;
  std::vector<double> up(static_cast<std::size_t>(fine) * fine);
  for (int r = 0; r < fine; ++r) {
    for (int c = 0; c < fine; ++c) {
      up[static_cast<std::size_t>(r) * fine + c] = world_->groundUp_m(
          tile->square.north_min_m + 0.5 * r * step_m, tile->square.east_min_m + 0.5 * c * step_m);
    }
  }
  const auto at = [&](int r, int c) { return up[static_cast<std::size_t>(r) * fine + c]; };
  double min_up = std::numeric_limits<double>::infinity();
  double max_up = -min_up;
  double error_m = 0.0;
  for (int r = 0; r < fine; ++r) {
    for (int c = 0; c < fine; ++c) {
      const double h = at(r, c);
      min_up = std::min(min_up, h);
      max_up = std::max(max_up, h);
      double mesh = h;
      if (r % 2 == 1 && c % 2 == 1) {
        mesh = 0.25 * (at(r - 1, c - 1) + at(r - 1, c + 1) + at(r + 1, c - 1) + at(r + 1, c + 1));
      } else if (r % 2 == 1) {
        mesh = 0.5 * (at(r - 1, c) + at(r + 1, c));
      } else if (c % 2 == 1) {
        mesh = 0.5 * (at(r, c - 1) + at(r, c + 1));
      } else {
        tile->height_up_m[static_cast<std::size_t>(r / 2) * n + c / 2] = static_cast<float>(h);
      }
      error_m = std::max(error_m, std::abs(h - mesh));
    }
  }
  tile->min_up_m = static_cast<float>(min_up);
  tile->max_up_m = static_cast<float>(max_up);
  tile->geometric_error_m = static_cast<float>(error_m);
  return tile;
}

std::shared_ptr<const TileGeometry> TileTree::geometry(const TileId& id) {
  const std::uint64_t key = id.key();
  {
    std::lock_guard lock(mutex_);
    const auto it = cache_.find(key);
    if (it != cache_.end()) {
      lru_.splice(lru_.begin(), lru_, it->second.position);
      return it->second.geometry;
    }
  }
  std::shared_ptr<const TileGeometry> tile = computeGeometry(id);
  const std::size_t bytes = sizeof(TileGeometry) + tile->height_up_m.size() * sizeof(float);
  std::lock_guard lock(mutex_);
  if (cache_.count(key) == 0) {
    lru_.push_front(key);
    cache_.emplace(key, Entry{tile, lru_.begin()});
    cache_bytes_ += bytes;
    const auto budget = static_cast<std::size_t>(params_.geometry_cache_mib * 1024 * 1024);
    while (cache_bytes_ > budget && lru_.size() > 1) {
      const auto victim = cache_.find(lru_.back());
      cache_bytes_ -=
          sizeof(TileGeometry) + victim->second.geometry->height_up_m.size() * sizeof(float);
      cache_.erase(victim);
      lru_.pop_back();
    }
  }
  return tile;
}

std::size_t TileTree::geometryCacheBytes() const {
  std::lock_guard lock(mutex_);
  return cache_bytes_;
}

std::size_t TileTree::geometryCacheEntries() const {
  std::lock_guard lock(mutex_);
  return cache_.size();
}

std::vector<TileId> TileTree::select(const LodView& view) {
  std::vector<TileId> selected;
  selectInto(TileId{}, view, selected);
  return selected;
}

void TileTree::selectInto(const TileId& id, const LodView& view, std::vector<TileId>& out) {
  const std::shared_ptr<const TileGeometry> tile = geometry(id);
  const GroundSquare& sq = tile->square;
  const Eigen::Vector3d box_min = tile->boxMin();
  const Eigen::Vector3d box_max = tile->boxMax();
  for (const Eigen::Vector4d& plane : view.frustum_planes) {
    // The box corner furthest along the plane's normal; if even it is outside, so is the box.
    const Eigen::Vector3d corner((plane.x() >= 0 ? box_max : box_min).x(),
                                 (plane.y() >= 0 ? box_max : box_min).y(),
                                 (plane.z() >= 0 ? box_max : box_min).z());
    if (plane.head<3>().dot(corner) + plane.w() < 0.0) return;
  }
  const double distance_m = std::max(tile->distanceFrom_m(view.camera_ned), 1e-3);
  const double pixels_per_m = view.focal_px / distance_m;
  const double texel_m = sq.size_m / params_.texture_px;
  const bool too_coarse = tile->geometric_error_m * pixels_per_m > params_.max_geometric_error_px ||
                          texel_m * pixels_per_m > params_.max_texel_px;
  if (too_coarse && id.level < max_level_) {
    for (int quadrant = 0; quadrant < 4; ++quadrant) selectInto(id.child(quadrant), view, out);
    return;
  }
  out.push_back(id);
}

bool TileTree::beneathObjects(const TileId& id, double objects_max_texel_m) const {
  return objects_max_texel_m > 0.0 &&
         squareOf(id).size_m / params_.texture_px <= objects_max_texel_m;
}

cv::Mat TileTree::imagery(const TileId& id, bool beneath_objects) const {
  const GroundSquare sq = squareOf(id);
  const double texel_m = sq.size_m / params_.texture_px;
  const GroundSquare bordered{sq.north_min_m - texel_m, sq.east_min_m - texel_m,
                              sq.size_m + 2 * texel_m};
  cv::Mat rgb;
  if (beneath_objects) {
    world_->imageryBeneathObjects(bordered, params_.texture_px + 2, rgb);
  } else {
    world_->imagery(bordered, params_.texture_px + 2, rgb);
  }
  return rgb;
}

}  // namespace nadir::terrain
