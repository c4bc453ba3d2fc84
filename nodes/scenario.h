#pragma once
// A scenario: everything one experiment needs, in one YAML file: the world
// and its origin, the vehicle and its route (or a recorded flight), the truth
// stream, the sensors, the cameras, the ground targets, how time runs and the
// bus. Built-in scenarios live in scenarios/*.yaml; any value can be
// overridden with "key=value" (the experiment axes: vehicle.airspeed_mps,
// vehicle.max_roll_rate_dps, vehicle.altitude_agl_m, camera.fps).

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/bus.h"
#include "core/params.h"
#include "nodes/camera/camera_node_params.h"
#include "nodes/camera/camera_rig.h"
#include "nodes/ppa/ppa_node_params.h"
#include "nodes/sim/sim_params.h"
#include "nodes/vo_feature/vo_feature_node.h"
#include "render/terrain_renderer.h"
#include "terrain/targets.h"
#include "terrain/tiles.h"
#include "terrain/world_factory.h"

namespace nadir::scenario {

struct TimeParams {
  // "realtime" paces the streams at speed x real time; "batch" runs as fast as possible.
  std::string mode = "realtime";
  double speed = 1.0;

  void visit(core::ParamVisitor& v);
};

struct ScenarioParams {
  // One line saying what the scenario flies.
  std::string description;
  // Vehicle, start, route, flight, truth, sensors and duration_s, at the top level.
  sim::SimParams sim;
  terrain::WorldParams world;
  // The main camera (named "down"), and any more by name.
  camera::CameraSpec camera;
  std::map<std::string, camera::CameraSpec> cameras;
  std::map<std::string, terrain::GroundTarget> targets;
  terrain::TileParams tiles;
  render::TerrainRendererParams renderer;
  // The VO nodes: the emulated SCAMP-5 vision sensor and the feature-based VO.
  ppa::PpaNodeParams ppa;
  vo::VoFeatureNodeParams vo_feature;
  TimeParams time;
  core::BusParams bus;

  void visit(core::ParamVisitor& v);
  // The main camera as "down" and the others under their names.
  std::map<std::string, camera::CameraSpec> allCameras() const;
};

// What the camera node needs from a scenario: its bus, the truth channel,
// the world, tiles, renderer, cameras and targets.
camera::CameraNodeParams cameraNodeParams(const ScenarioParams& scenario);

// The world frame's geodetic origin (reads the DEM only when the origin is its centre).
core::Geodetic scenarioOrigin(const ScenarioParams& scenario);

// North and east of the scenario's concentric targets (the known targets a
// VO node may correct its position with), geodetic ones resolved in frame.
std::vector<Eigen::Vector2d> knownTargets(const ScenarioParams& scenario,
                                          const core::LocalNedFrame& frame);

// The folder of the built-in scenarios: $NADIR_SCENARIO_DIR if set, else the
// project's scenarios/ folder.
std::string scenarioDirectory();
// Names of the built-in scenarios, sorted.
std::vector<std::string> builtinScenarioNames();
// A path to an existing file as given, else the built-in NAME; throws
// core::ParamError listing the built-in names if neither exists.
std::string resolveScenarioPath(const std::string& name_or_path);

// Loads a scenario (a built-in name or a YAML path) and applies the overrides
// ("key=value"); file paths in it are relative to its folder. Throws
// core::ParamError naming the file, line and key of an unknown key, a wrong
// type or a value out of range. (Whether the route can be flown is checked by
// sim::Simulator, which needs the world.)
ScenarioParams loadScenario(const std::string& name_or_path,
                            const std::vector<std::string>& overrides = {});

}  // namespace nadir::scenario
