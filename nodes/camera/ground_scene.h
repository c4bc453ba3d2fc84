#pragma once
// What every program that renders the ground sets up the same way: the world,
// a headless GL context, the tiles, the terrain renderer, the ground targets
// and the course's upright boards.

#include <map>
#include <memory>
#include <string>

#include "render/egl_context.h"
#include "render/terrain_renderer.h"
#include "terrain/course.h"
#include "terrain/targets.h"
#include "terrain/tiles.h"
#include "terrain/world_factory.h"

namespace nadir::camera {

struct GroundScene {
  // Throws what makeWorld and the GL context throw, naming what is wrong.
  GroundScene(const terrain::WorldParams& world_params, const terrain::TileParams& tile_params,
              const render::TerrainRendererParams& renderer_params,
              const std::map<std::string, terrain::GroundTarget>& targets,
              const terrain::CourseParams& course = {});

  terrain::BuiltWorld built;
  render::HeadlessGlContext context;
  std::shared_ptr<terrain::TileTree> tiles;
  render::TerrainRenderer terrain;
};

}  // namespace nadir::camera
