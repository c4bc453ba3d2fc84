#pragma once
// A quadtree of ground tiles over a World, and the choice of which tiles to
// draw for a view: refine a tile while its mesh error or its texel, seen from
// the camera, is larger than a pixel budget. Everything here is a pure
// function of the World and the view, so the same pose always selects the same
// tiles (the renderer's determinism rests on it).

#include <array>
#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "core/params.h"
#include "terrain/world.h"

namespace nadir::terrain {

struct TileId {
  int level = 0;  // 0 = the root, covering the whole quadtree square
  int ix = 0;     // column, from the west
  int iy = 0;     // row, from the south

  bool operator==(const TileId&) const = default;
  TileId child(int quadrant) const;  // quadrant: bit 0 east, bit 1 north
  std::uint64_t key() const;
};

struct TileParams {
  // Mesh quads along a tile's edge.
  int mesh_quads = 8;
  // Texture pixels along a tile's edge (plus one border texel each side).
  int texture_px = 512;
  // Refine while a tile's mesh error seen from the camera exceeds this, px.
  double max_geometric_error_px = 1.0;
  // Refine while one texel covers more than this many image pixels.
  double max_texel_px = 1.0;
  // Memory for cached tile geometry, MiB.
  double geometry_cache_mib = 64.0;

  void visit(core::ParamVisitor& v);
};

// The mesh of a tile: (mesh_quads + 1)^2 heights (up, m) on a regular grid,
// row 0 at the south edge, with its error against the finer ground.
struct TileGeometry {
  TileId id;
  GroundSquare square;
  int vertices_per_edge = 0;
  std::vector<float> height_up_m;
  float min_up_m = 0.0f;
  float max_up_m = 0.0f;
  // Largest height difference between the mesh and the ground between its vertices, m.
  float geometric_error_m = 0.0f;

  // Corners of the tile's bounding box in the world frame (NED).
  Eigen::Vector3d boxMin() const;
  Eigen::Vector3d boxMax() const;
  // Distance from a point to the nearest point of that box, m (0 inside).
  double distanceFrom_m(const Eigen::Vector3d& p_ned) const;
};

// A view for tile selection: camera centre, frustum planes (inward normals,
// n.dot(p) + d >= 0 inside) in the world frame, and the focal length in pixels.
struct LodView {
  Eigen::Vector3d camera_ned = Eigen::Vector3d::Zero();
  std::array<Eigen::Vector4d, 6> frustum_planes{};
  double focal_px = 1000.0;
};

class TileTree {
 public:
  TileTree(std::shared_ptr<const World> world, const TileParams& params);

  const World& world() const { return *world_; }
  const TileParams& params() const { return params_; }
  // The square the root tile covers (the world extent's bounding square).
  GroundSquare rootSquare() const { return root_; }
  GroundSquare squareOf(const TileId& id) const;
  // Whether 3D objects stand on a tile, its imagery then beneath them
  // (World::imageryBeneathObjects): its texel is at most objects_max_texel_m
  // (0: on none).
  bool beneathObjects(const TileId& id, double objects_max_texel_m) const;
  int maxLevel() const { return max_level_; }

  // Tiles to draw for the view, coarse to fine, in a fixed order.
  std::vector<TileId> select(const LodView& view);

  // The mesh of a tile, from the cache or computed now. Thread-safe.
  std::shared_ptr<const TileGeometry> geometry(const TileId& id);

  // The texture of a tile: (texture_px + 2)^2 RGB, the border texel one texel
  // outside the tile's square on each side, north up (row 0 at the north).
  // beneath_objects: World::imageryBeneathObjects.
  cv::Mat imagery(const TileId& id, bool beneath_objects = false) const;

  std::size_t geometryCacheBytes() const;
  std::size_t geometryCacheEntries() const;

 private:
  std::shared_ptr<TileGeometry> computeGeometry(const TileId& id) const;
  void selectInto(const TileId& id, const LodView& view, std::vector<TileId>& out);

  std::shared_ptr<const World> world_;
  TileParams params_;
  GroundSquare root_;
  int max_level_ = 0;

  mutable std::mutex mutex_;
  using LruList = std::list<std::uint64_t>;
  struct Entry {
    std::shared_ptr<const TileGeometry> geometry;
    LruList::iterator position;
  };
  std::unordered_map<std::uint64_t, Entry> cache_;
  LruList lru_;
  std::size_t cache_bytes_ = 0;
};

}  // namespace nadir::terrain
