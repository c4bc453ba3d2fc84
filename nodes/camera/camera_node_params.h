#pragma once
// Everything nadir-camera reads from its YAML file (or a scenario) and --set overrides.

#include <map>
#include <string>

#include "core/params.h"
#include "nodes/camera/camera_rig.h"
#include "render/terrain_renderer.h"
#include "terrain/course.h"
#include "terrain/targets.h"
#include "terrain/tiles.h"
#include "terrain/world_factory.h"

namespace nadir::camera {

struct CameraNodeParams {
  std::string pose_channel = "POSE_TRUTH";
  terrain::WorldParams world;
  terrain::TileParams tiles;
  render::TerrainRendererParams renderer;
  // Cameras by name; none given: one "down" camera with CameraSpec's defaults.
  std::map<std::string, CameraSpec> cameras;
  std::map<std::string, terrain::GroundTarget> targets;
  terrain::CourseParams course;

  void visit(core::ParamVisitor& v) {
    v.field("pose_channel", &pose_channel,
            {.doc = "pose_t channel of the body the cameras ride on"});
    core::visitGroup(v, "world", "the terrain", world);
    core::visitGroup(v, "tiles", "terrain tiles and levels of detail", tiles);
    core::visitGroup(v, "renderer", "terrain drawing", renderer);
    core::visitGroupMap(v, "cameras", "cameras by name", cameras);
    core::visitGroupMap(v, "targets", "ground targets by name", targets);
    core::visitGroup(v, "course", "upright gates, slalom boards and decoys", course);
  }
};

}  // namespace nadir::camera
