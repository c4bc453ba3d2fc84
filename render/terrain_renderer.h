#pragma once
// Draws the ground (tiles of a terrain::TileTree) seen by a pinhole camera
// into whatever framebuffer and GL context are current: the headless camera
// and the Qt viewer share it.

#include <cstdint>
#include <list>
#include <memory>
#include <unordered_map>
#include <vector>

#include <Eigen/Geometry>

#include "core/params.h"
#include "render/camera_model.h"
#include "terrain/course.h"
#include "terrain/targets.h"
#include "terrain/tile_prefetcher.h"
#include "terrain/tiles.h"

namespace nadir::render {

class GroundObjectRenderer;
class CourseBoardRenderer;

struct TerrainRendererParams {
  // GPU memory for tile meshes and textures, MiB (system memory on llvmpipe).
  double tile_cache_mib = 512.0;
  // Strength of the sub-imagery detail, 0..1 (contrast of the detail pattern).
  double detail_contrast = 0.1;
  // Trees and buildings stand up as 3D objects (World::objects) on tiles whose
  // texel is at most objects_max_texel_m; coarser tiles are far enough that
  // the imagery's tops alone are drawn.
  bool objects_3d = false;
  double objects_max_texel_m = 1.5;
  // Make the imagery of the tiles a camera is about to see on a worker thread,
  // from spare cycles (terrain/tile_prefetcher.h); the pixels are the same.
  bool prefetch_tiles = true;

  void visit(core::ParamVisitor& v);
};

// What one draw needs to know about the camera.
struct DrawView {
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  // Pinhole part only: the renderer draws undistorted images.
  CameraIntrinsics intrinsics;
  double near_m = 0.5;
  double far_m = 20000.0;
  double gain = 1.0;
  bool ground_detail = true;
  // Write luminance into the red channel (for gray cameras) instead of RGB.
  bool gray = true;
};

struct DrawStats {
  int tiles = 0;
  int triangles = 0;  // the terrain's and the objects'
  int tiles_uploaded = 0;
  int objects = 0;
  int boards = 0;
};

class TerrainRenderer {
 public:
  // Needs a current OpenGL 4.5 core context; keep it current for every call.
  TerrainRenderer(std::shared_ptr<terrain::TileTree> tiles, const TerrainRendererParams& params);
  ~TerrainRenderer();
  TerrainRenderer(const TerrainRenderer&) = delete;
  TerrainRenderer& operator=(const TerrainRenderer&) = delete;

  // Clears and draws into the current framebuffer (viewport = intrinsics size).
  DrawStats draw(const DrawView& view);

  // Ground targets drawn on top of the terrain from now on (replacing earlier ones).
  void setTargets(const std::vector<terrain::GroundTarget>& targets);
  // Upright course boards drawn from now on (replacing earlier ones), after the
  // ground and its targets, depth-tested.
  void setBoards(const std::vector<terrain::CourseBoard>& boards);

  // Tile selection for a view (also what draw() uses).
  std::vector<terrain::TileId> visibleTiles(const DrawView& view);
  // The views a camera expects to draw next, soonest first: their tiles'
  // imagery is made ahead (with prefetch_tiles). Replaces the views given before.
  void expect(const std::vector<DrawView>& views);
  // What makes tiles ahead; null without prefetch_tiles.
  const terrain::TilePrefetcher* prefetcher() const { return prefetcher_.get(); }

  std::size_t gpuBytes() const { return gpu_bytes_; }
  std::size_t gpuTiles() const { return gpu_tiles_.size(); }
  terrain::TileTree& tiles() { return *tiles_; }

 private:
  struct GpuTile;
  GpuTile& acquire(const terrain::TileId& id, int& uploaded);
  // Tiles with texels this fine or finer have 3D objects standing on them (0: none).
  double objectsMaxTexel_m() const {
    return params_.objects_3d ? params_.objects_max_texel_m : 0.0;
  }
  void evictBeyondBudget(const std::vector<terrain::TileId>& in_use);

  std::shared_ptr<terrain::TileTree> tiles_;
  TerrainRendererParams params_;
  std::unique_ptr<terrain::TilePrefetcher> prefetcher_;
  unsigned int program_plain_ = 0;
  unsigned int program_detail_ = 0;
  unsigned int index_buffer_ = 0;
  int index_count_ = 0;
  unsigned int detail_texture_ = 0;
  struct GpuTarget;
  void drawTargets(const DrawView& view, const Eigen::Matrix4d& clip_from_camera);
  unsigned int program_target_ = 0;
  std::vector<std::unique_ptr<GpuTarget>> targets_;
  // nearest_m: each visible tile's distance from the camera.
  void drawObjects(const DrawView& view, const Eigen::Matrix4d& clip_from_camera,
                   const std::vector<terrain::TileId>& visible,
                   const std::vector<double>& nearest_m, DrawStats& stats);
  std::unique_ptr<GroundObjectRenderer> objects_;
  std::unique_ptr<CourseBoardRenderer> boards_;
  std::unordered_map<std::uint64_t, std::unique_ptr<GpuTile>> gpu_tiles_;
  std::list<std::uint64_t> lru_;
  std::size_t gpu_bytes_ = 0;
};

// The frustum planes of a view, for tile selection (inward normals, world frame).
terrain::LodView lodViewOf(const DrawView& view);

}  // namespace nadir::render
