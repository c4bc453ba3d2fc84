#include "nodes/scenario.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>

namespace nadir::scenario {
namespace {

namespace fs = std::filesystem;

// A relative path from a scenario file is relative to that file's folder.
void resolveRelative(std::string& path, const fs::path& folder) {
  if (path.empty() || fs::path(path).is_absolute()) return;
  path = (folder / path).lexically_normal().string();
}

}  // namespace

void TimeParams::visit(core::ParamVisitor& v) {
  v.field("mode", &mode,
          {.doc = "realtime (paced at speed x real time) or batch (as fast as possible)",
           .choices = {"realtime", "batch"}});
  v.field("speed", &speed, {.doc = "realtime: multiple of real time", .min = 0.01, .max = 1000});
}

void ScenarioParams::visit(core::ParamVisitor& v) {
  v.field("description", &description, {.doc = "what the scenario flies"});
  sim.visit(v);
  core::visitGroup(v, "world", "the terrain and the world frame's origin", world);
  core::visitGroup(v, "camera", "the main camera (\"down\")", camera);
  core::visitGroupMap(v, "cameras", "more cameras by name", cameras);
  core::visitGroupMap(v, "targets", "ground targets by name", targets);
  core::visitGroup(v, "tiles", "terrain tiles and levels of detail", tiles);
  core::visitGroup(v, "renderer", "terrain drawing", renderer);
  core::visitGroup(v, "ppa", "the emulated SCAMP-5 vision sensor (nadir-ppa)", ppa);
  core::visitGroup(v, "vo_feature", "the feature-based VO (nadir-vo-feature)", vo_feature);
  core::visitGroup(v, "time", "how sim time runs", time);
  core::visitGroup(v, "bus", "where the streams go", bus);
}

std::map<std::string, camera::CameraSpec> ScenarioParams::allCameras() const {
  std::map<std::string, camera::CameraSpec> all = cameras;
  all["down"] = camera;
  return all;
}

camera::CameraNodeParams cameraNodeParams(const ScenarioParams& scenario) {
  camera::CameraNodeParams params;
  params.bus = scenario.bus;
  params.pose_channel = scenario.sim.truth.channel;
  params.world = scenario.world;
  params.tiles = scenario.tiles;
  params.renderer = scenario.renderer;
  params.cameras = scenario.allCameras();
  params.targets = scenario.targets;
  return params;
}

core::Geodetic scenarioOrigin(const ScenarioParams& scenario) {
  if (scenario.world.kind == "files" && scenario.world.origin_at_dem_centre) {
    return terrain::makeWorld(scenario.world).origin;
  }
  return core::geodeticFromDegrees(scenario.world.origin_lat_deg, scenario.world.origin_lon_deg,
                                   scenario.world.origin_alt_m);
}

std::vector<Eigen::Vector2d> knownTargets(const ScenarioParams& scenario,
                                          const core::LocalNedFrame& frame) {
  std::vector<terrain::GroundTarget> targets;
  for (const auto& [name, target] : scenario.targets) {
    if (target.kind == "concentric") targets.push_back(target);
  }
  terrain::resolveGeodeticTargets(targets, frame);
  std::vector<Eigen::Vector2d> positions;
  for (const terrain::GroundTarget& target : targets) {
    positions.emplace_back(target.north_m, target.east_m);
  }
  return positions;
}

std::string scenarioDirectory() {
  if (const char* dir = std::getenv("NADIR_SCENARIO_DIR"); dir != nullptr && *dir != '\0') {
    return dir;
  }
  return NADIR_SOURCE_SCENARIO_DIR;
}

std::vector<std::string> builtinScenarioNames() {
  std::vector<std::string> names;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(scenarioDirectory(), error)) {
    if (entry.path().extension() == ".yaml") names.push_back(entry.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

std::string resolveScenarioPath(const std::string& name_or_path) {
  if (fs::is_regular_file(name_or_path)) return name_or_path;
  const fs::path builtin = fs::path(scenarioDirectory()) / (name_or_path + ".yaml");
  if (name_or_path.find('/') == std::string::npos && fs::is_regular_file(builtin)) {
    return builtin.string();
  }
  std::string names;
  for (const std::string& name : builtinScenarioNames()) {
    names += (names.empty() ? "" : ", ") + name;
  }
  throw core::ParamError("scenario '" + name_or_path +
                         "': no such file and no built-in scenario of that name (built in: " +
                         (names.empty() ? "none found in " + scenarioDirectory() : names) + ")");
}

ScenarioParams loadScenario(const std::string& name_or_path,
                            const std::vector<std::string>& overrides) {
  const std::string path = resolveScenarioPath(name_or_path);
  ScenarioParams params;
  core::applyYamlFile(path, [&params](core::ParamVisitor& v) { params.visit(v); });
  const fs::path folder = fs::path(path).parent_path();
  for (std::string* file : {&params.world.dem_path, &params.world.imagery_path,
                            &params.world.imagery_red_path, &params.world.imagery_green_path,
                            &params.world.imagery_blue_path, &params.sim.flight.path}) {
    resolveRelative(*file, folder);
  }
  core::applyAssignments(params, overrides);
  return params;
}

}  // namespace nadir::scenario
