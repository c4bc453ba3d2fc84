#pragma once
// A scenario: everything one experiment needs, in one YAML file: the world and
// its origin, the vehicle and its route (or a recorded flight), the truth
// stream, the sensors, the cameras, the ground targets, how time runs, the bus,
// and a group for each processing node of the registry (ppa, vo_feature, ...).
// Built-in scenarios live in scenarios/*.yaml; any value can be overridden with
// "key=value" (the experiment axes: vehicle.airspeed_mps,
// vehicle.max_roll_rate_dps, vehicle.altitude_agl_m, camera.fps).

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "calib/virtual/virtual_board.h"
#include "core/bus.h"
#include "core/geodesy.h"
#include "core/params.h"
#include "nodes/camera/camera_rig.h"
#include "nodes/scenario_files.h"
#include "nodes/sim/sim_params.h"
#include "render/terrain_renderer.h"
#include "terrain/course.h"
#include "terrain/targets.h"
#include "terrain/tiles.h"
#include "terrain/world_factory.h"

namespace nadir::nodes {

// A processing node's group in a scenario.
struct NodeGroup {
  std::string name;
  std::string doc;
  core::AnyParams params;
};

struct ScenarioParams {
  // Every registry entry's group with its defaults.
  ScenarioParams();

  // One line saying what the scenario flies.
  std::string description;
  // Vehicle, start, route, flight, truth, sensors and duration_s, at the top level.
  sim::SimParams sim;
  terrain::WorldParams world;
  // The main camera (named "down"), and any more by name.
  camera::CameraSpec camera;
  std::map<std::string, camera::CameraSpec> cameras;
  std::map<std::string, terrain::GroundTarget> targets;
  // Upright boards for a ground rover: gates, slalom boards, decoys.
  terrain::CourseParams course;
  terrain::TileParams tiles;
  render::TerrainRendererParams renderer;
  // The processing nodes, in registry order.
  std::vector<NodeGroup> nodes;
  sim::TimeParams time;
  core::BusParams bus;
  // The poses the virtual checkerboard is seen from (nadir calib --virtual;
  // world.kind checkerboard).
  calib::VirtualViewParams calibration;

  void visit(core::ParamVisitor& v);
  // The main camera as "down" and the others under their names.
  std::map<std::string, camera::CameraSpec> allCameras() const;

  // A node's group as its params type; throws std::logic_error for a name or a
  // type the scenario does not have.
  template <class P>
  P& node(std::string_view name) {
    return group(name).params.as<P>();
  }
  template <class P>
  const P& node(std::string_view name) const {
    return const_cast<ScenarioParams*>(this)->group(name).params.as<P>();
  }

 private:
  NodeGroup& group(std::string_view name);
};

// The world frame's geodetic origin (reads the DEM only when the origin is its centre).
core::Geodetic scenarioOrigin(const ScenarioParams& scenario);

// North and east of the scenario's concentric targets (the known targets a
// VO node may correct its position with), geodetic ones resolved in frame.
std::vector<Eigen::Vector2d> knownTargets(const ScenarioParams& scenario,
                                          const core::LocalNedFrame& frame);

// Loads a scenario (a built-in name or a YAML path) and applies the overrides
// ("key=value"); file paths in it are relative to its folder. Throws
// core::ParamError naming the file, line and key of an unknown key, a wrong
// type or a value out of range. (Whether the route can be flown is checked by
// sim::Simulator, which needs the world.)
ScenarioParams loadScenario(const std::string& name_or_path,
                            const std::vector<std::string>& overrides = {});

}  // namespace nadir::nodes
