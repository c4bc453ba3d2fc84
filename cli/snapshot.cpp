#include "cli/snapshot.h"

#include "cli/commands.h"

#include <CLI/CLI.hpp>
#include <memory>

#include <cmath>
#include <iostream>
#include <map>
#include <numbers>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/frames.h"
#include "core/params.h"
#include "nodes/camera/ground_scene.h"
#include "render/camera_renderer.h"
#include "terrain/targets.h"
#include "terrain/world_factory.h"

namespace nadir::cli {
namespace {

struct SnapshotParams {
  terrain::WorldParams world;
  terrain::TileParams tiles;
  render::TerrainRendererParams renderer;
  render::CameraParams camera;
  std::map<std::string, terrain::GroundTarget> targets;
  terrain::CourseParams course;
  double north_m = 0.0;
  double east_m = 0.0;
  double agl_m = 300.0;
  double roll_deg = 0.0;
  double pitch_deg = 0.0;
  double yaw_deg = 0.0;

  void visit(core::ParamVisitor& v) {
    core::visitGroup(v, "world", "the terrain", world);
    core::visitGroup(v, "tiles", "terrain tiles and levels of detail", tiles);
    core::visitGroup(v, "renderer", "terrain drawing", renderer);
    core::visitGroup(v, "camera", "the camera, looking down from the body", camera);
    core::visitGroupMap(v, "targets", "ground targets by name", targets);
    core::visitGroup(v, "course", "upright gates, slalom boards and decoys", course);
    v.field("north_m", &north_m,
            {.doc = "body position north of the origin, m", .min = -1e6, .max = 1e6});
    v.field("east_m", &east_m,
            {.doc = "body position east of the origin, m", .min = -1e6, .max = 1e6});
    v.field("agl_m", &agl_m, {.doc = "height above the ground below, m", .min = 0.1, .max = 1e5});
    v.field("roll_deg", &roll_deg, {.doc = "body roll, deg", .min = -180, .max = 180});
    v.field("pitch_deg", &pitch_deg, {.doc = "body pitch, deg", .min = -90, .max = 90});
    v.field("yaw_deg", &yaw_deg, {.doc = "body heading from north, deg", .min = -360, .max = 360});
  }
};

}  // namespace

int runSnapshot(const std::string& config_path, const std::vector<std::string>& overrides,
                const std::string& out_path) {
  SnapshotParams params;
  const auto visit = [&params](core::ParamVisitor& v) { params.visit(v); };
  if (!config_path.empty()) core::applyYamlFile(config_path, visit);
  core::applyAssignments(params, overrides);

  camera::GroundScene scene(params.world, params.tiles, params.renderer, params.targets,
                            params.course);
  const terrain::BuiltWorld& built = scene.built;
  render::CameraRenderer camera(scene.terrain, params.camera);

  constexpr double kDeg = std::numbers::pi / 180.0;
  const double ground_up_m = built.world->groundUp_m(params.north_m, params.east_m);
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  T_world_cam.linear() = core::rotationFromRpy({params.roll_deg * kDeg, params.pitch_deg * kDeg,
                                                params.yaw_deg * kDeg}) *
                         core::rotationBodyFromDownCamera();
  T_world_cam.translation() =
      Eigen::Vector3d(params.north_m, params.east_m, -(ground_up_m + params.agl_m));
  const render::RenderedImage frame = camera.render(T_world_cam, 0);

  cv::Mat out = frame.image;
  if (out.channels() == 3) cv::cvtColor(frame.image, out, cv::COLOR_RGB2BGR);
  if (!cv::imwrite(out_path, out)) {
    std::cerr << "nadir snapshot: error: cannot write " << out_path << "\n";
    return 1;
  }
  std::cout << "wrote " << out_path << ": " << frame.image.cols << "x" << frame.image.rows << " "
            << params.camera.pixel_format << ", " << built.description << ", at north "
            << params.north_m << " m, east " << params.east_m << " m, " << params.agl_m
            << " m above ground (" << frame.stats.tiles << " tiles, " << frame.stats.triangles
            << " triangles)\n";
  return 0;
}

void addSnapshotCommand(CLI::App& app) {
  struct Options {
    std::string config;
    std::string out = "snapshot.png";
    std::vector<std::string> overrides;
  };
  auto options = std::make_shared<Options>();
  auto* snapshot = app.add_subcommand(
      "snapshot", "Render what a downward camera sees from one pose over a world, as a PNG");
  snapshot->add_option("--config", options->config, "YAML parameter file")
      ->check(CLI::ExistingFile);
  snapshot->add_option("--set", options->overrides, "override a parameter: key=value (repeatable)");
  snapshot->add_option("--out", options->out, "PNG to write")->capture_default_str();
  snapshot->callback([options] {
    const int status = runSnapshot(options->config, options->overrides, options->out);
    if (status != 0) throw CLI::RuntimeError(status);
  });
}

}  // namespace nadir::cli
