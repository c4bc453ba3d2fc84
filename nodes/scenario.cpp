#include "nodes/scenario.h"

#include "nodes/nav/nav_node.h"
#include "nodes/registry.h"

#include "core/sun.h"
#include "core/utc_time.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <optional>
#include <stdexcept>

namespace nadir::nodes {
namespace {

namespace fs = std::filesystem;

// A relative path from a scenario file is relative to that file's folder.
void resolveRelative(std::string& path, const fs::path& folder) {
  if (path.empty() || fs::path(path).is_absolute()) return;
  path = (folder / path).lexically_normal().string();
}

// An empty time.start_utc becomes kDefaultStartDate at 10:00 local mean solar
// time at the origin; over the procedural world, the sun's angles not given
// become where the sun stands at the origin then.
void resolveStartAndSun(ScenarioParams& params, const std::vector<std::string>& given) {
  constexpr double kDeg = 180.0 / std::numbers::pi;
  const auto is_given = [&given](std::string_view key) {
    return std::find(given.begin(), given.end(), key) != given.end();
  };
  std::optional<core::Geodetic> origin;
  const auto origin_deg = [&]() {
    if (!origin) origin = terrain::approximateOrigin(params.world);
    return std::pair{origin->lat_rad * kDeg, origin->lon_rad * kDeg};
  };
  if (params.time.start_utc.empty()) {
    const std::int64_t midnight =
        core::utimeFromUtc(std::string(sim::kDefaultStartDate) + "T00:00:00Z");
    const double hours = 10.0 - origin_deg().second / 15.0;
    params.time.start_utc = core::utcFromUtime(midnight + std::llround(hours * 3600.0) * 1'000'000);
  }
  const std::int64_t start_utime = sim::runStartUtime(params.time);
  if (params.world.kind != "procedural" || is_given("world.procedural.sun_azimuth_deg") ||
      is_given("world.procedural.sun_elevation_deg")) {
    return;
  }
  const auto [lat_deg, lon_deg] = origin_deg();
  const core::SunPosition sun = core::sunPosition(start_utime, lat_deg, lon_deg);
  constexpr double kLowestSun_deg = 15.0;
  if (sun.elevation_deg < kLowestSun_deg) {
    throw core::ParamError(
        "time.start_utc " + params.time.start_utc + ": the sun is " +
        std::to_string(sun.elevation_deg) +
        " deg above the horizon at the origin; the "
        "procedural world is lit from at least 15 deg: choose a time of day or give "
        "world.procedural.sun_azimuth_deg and sun_elevation_deg");
  }
  params.world.procedural.sun_azimuth_deg = sun.azimuth_deg;
  params.world.procedural.sun_elevation_deg = sun.elevation_deg;
}

}  // namespace

ScenarioParams::ScenarioParams() {
  for (const auto& entry : registry()) {
    if (std::optional<core::AnyParams> group = entry->scenarioGroup()) {
      nodes.push_back({entry->info().name, entry->scenarioGroupDoc(), std::move(*group)});
    }
  }
}

NodeGroup& ScenarioParams::group(std::string_view name) {
  for (NodeGroup& group : nodes) {
    if (group.name == name) return group;
  }
  throw std::logic_error("the scenario has no node group " + std::string(name));
}

void ScenarioParams::visit(core::ParamVisitor& v) {
  v.field("description", &description, {.doc = "what the scenario flies"});
  sim.visit(v);
  core::visitGroup(v, "world", "the terrain and the world frame's origin", world);
  core::visitGroup(v, "camera", "the main camera (\"down\")", camera);
  core::visitGroupMap(v, "cameras", "more cameras by name", cameras);
  core::visitGroupMap(v, "targets", "ground targets by name", targets);
  core::visitGroup(v, "course", "upright gates, slalom boards and decoys for a ground rover",
                   course);
  core::visitGroup(v, "tiles", "terrain tiles and levels of detail", tiles);
  core::visitGroup(v, "renderer", "terrain drawing", renderer);
  for (NodeGroup& group : nodes) core::visitGroup(v, group.name, group.doc, group.params);
  core::visitGroup(v, "time", "how sim time runs", time);
  core::visitGroup(v, "bus", "where the streams go", bus);
  core::visitGroup(v, "calibration",
                   "the virtual checkerboard's views (nadir calib --virtual; world.kind "
                   "checkerboard)",
                   calibration);
}

std::map<std::string, camera::CameraSpec> ScenarioParams::allCameras() const {
  std::map<std::string, camera::CameraSpec> all = cameras;
  all["down"] = camera;
  return all;
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

ScenarioParams loadScenario(const std::string& name_or_path,
                            const std::vector<std::string>& overrides) {
  const std::string path = resolveScenarioPath(name_or_path);
  ScenarioParams params;
  core::applyYamlFile(path, [&params](core::ParamVisitor& v) { params.visit(v); });
  const fs::path folder = fs::path(path).parent_path();
  terrain::resolvePathsFrom(params.world, folder.string());
  resolveRelative(params.sim.flight.path, folder);
  resolveRelative(params.camera.calibration_file, folder);
  for (auto& [name, spec] : params.cameras) resolveRelative(spec.calibration_file, folder);
  core::applyAssignments(params, overrides);
  const std::vector<std::string> given = core::givenKeys(path, overrides);
  terrain::markGivenOrigin(params.world, given);
  resolveStartAndSun(params, given);
  // The guidance's source is a navigation choice, under nav in a scenario.
  params.sim.guidance.source = params.node<nav::NavNodeParams>("nav").source;
  return params;
}

}  // namespace nadir::nodes
