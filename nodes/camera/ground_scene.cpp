#include "nodes/camera/ground_scene.h"

#include <vector>

namespace nadir::camera {

GroundScene::GroundScene(const terrain::WorldParams& world_params,
                         const terrain::TileParams& tile_params,
                         const render::TerrainRendererParams& renderer_params,
                         const std::map<std::string, terrain::GroundTarget>& targets,
                         const terrain::CourseParams& course)
    : built(terrain::makeWorld(world_params)),
      tiles(std::make_shared<terrain::TileTree>(built.world, tile_params)),
      terrain(tiles, renderer_params) {
  std::vector<terrain::GroundTarget> placed;
  for (const auto& [name, target] : targets) placed.push_back(target);
  terrain::resolveGeodeticTargets(placed, core::LocalNedFrame(built.origin));
  terrain.setTargets(placed);
  const std::vector<terrain::CourseBoard> boards = terrain::courseBoards(course);
  if (!boards.empty()) terrain.setBoards(boards);
}

}  // namespace nadir::camera
