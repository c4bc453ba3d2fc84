// nadir-camera: renders the virtual cameras riding on a body whose true pose
// arrives over LCM, and publishes their images and camera_info_t. Wiring only.
//
//   nadir-camera [--config FILE] [--set key=value ...]
//   nadir-camera --scenario NAME [--set key=value ...]   (the scenario's world and cameras)

#include <CLI/CLI.hpp>

#include <atomic>
#include <csignal>
#include <iostream>

#include "core/bus.h"
#include "nodes/camera/camera_node_params.h"
#include "nodes/camera/camera_node.h"
#include "nodes/scenario.h"

namespace {

std::atomic<bool> g_stop{false};

void onSignal(int) { g_stop = true; }

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"nadir-camera: virtual downward cameras over LCM"};
  std::string config_path;
  std::string scenario_name;
  std::vector<std::string> overrides;
  auto* config =
      app.add_option("--config", config_path, "YAML parameter file")->check(CLI::ExistingFile);
  app.add_option("--scenario", scenario_name,
                 "take the world, cameras, targets and bus from this scenario (--set applies "
                 "to the scenario's keys)")
      ->excludes(config);
  app.add_option("--set", overrides, "override a parameter: key=value (repeatable)");
  CLI11_PARSE(app, argc, argv);

  try {
    nadir::camera::CameraNodeParams params;
    if (!scenario_name.empty()) {
      params = nadir::scenario::cameraNodeParams(
          nadir::scenario::loadScenario(scenario_name, overrides));
    } else {
      const auto visit = [&params](nadir::core::ParamVisitor& v) { params.visit(v); };
      if (!config_path.empty()) nadir::core::applyYamlFile(config_path, visit);
      nadir::core::applyAssignments(params, overrides);
    }
    if (params.cameras.empty()) params.cameras["down"] = nadir::camera::CameraSpec{};
    std::cout << "nadir-camera parameters:\n" << nadir::core::formatParamsOf(params) << std::flush;

    auto bus = nadir::core::openBus(params.bus);
    nadir::camera::CameraNode node(*bus, params);
    std::cout << "world: " << node.scene().built.description << "\n"
              << "rendering with " << node.scene().context.info().gl_renderer << "\n"
              << "bus: " << bus->url() << ", poses from " << params.pose_channel << std::endl;
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    while (!g_stop) bus->handle(std::chrono::milliseconds(100));
    const auto stats = bus->stats();
    const auto pose_stats = stats.find(params.pose_channel);
    if (node.badPoses() > 0) {
      std::cerr << "nadir-camera: first bad pose: " << node.firstBadPose() << "\n";
    }
    std::cout << "nadir-camera: published " << node.framesPublished() << " frames; dropped "
              << node.badPoses() << " bad poses and "
              << (pose_stats == stats.end() ? 0 : pose_stats->second.decode_errors)
              << " undecodable messages" << std::endl;
  } catch (const std::exception& error) {
    std::cerr << "nadir-camera: error: " << error.what() << std::endl;
    return 1;
  }
  return 0;
}
