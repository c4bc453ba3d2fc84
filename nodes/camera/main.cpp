// nadir-camera: renders the virtual cameras riding on a body whose true pose
// arrives over LCM, and publishes their images and camera_info_t. Wiring only.
//
//   nadir-camera [--config FILE] [--set key=value ...]
//   nadir-camera --scenario NAME [--set key=value ...]   (the scenario's world and cameras)

#include <CLI/CLI.hpp>

#include <atomic>
#include <csignal>
#include <iostream>
#include <map>

#include "core/bus.h"
#include "nodes/camera/camera_messages.h"
#include "nodes/camera/camera_node_params.h"
#include "nodes/camera/camera_rig.h"
#include "nodes/camera/ground_scene.h"
#include "scenario/scenario.h"

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
      const nadir::scenario::ScenarioParams scenario =
          nadir::scenario::loadScenario(scenario_name, overrides);
      params.bus = scenario.bus;
      params.pose_channel = scenario.sim.truth.channel;
      params.world = scenario.world;
      params.tiles = scenario.tiles;
      params.renderer = scenario.renderer;
      params.cameras = scenario.allCameras();
      params.targets = scenario.targets;
    } else {
      const auto visit = [&params](nadir::core::ParamVisitor& v) { params.visit(v); };
      if (!config_path.empty()) nadir::core::applyYamlFile(config_path, visit);
      nadir::core::applyAssignments(params, overrides);
    }
    if (params.cameras.empty()) params.cameras["down"] = nadir::camera::CameraSpec{};
    std::cout << "nadir-camera parameters:\n" << nadir::core::formatParamsOf(params) << std::flush;

    nadir::camera::GroundScene scene(params.world, params.tiles, params.renderer, params.targets);
    std::cout << "world: " << scene.built.description << "\n"
              << "rendering with " << scene.context.info().gl_renderer << "\n";
    nadir::camera::CameraRig rig(scene.terrain, params.cameras);

    auto bus = nadir::core::openBus(params.bus);
    std::cout << "bus: " << bus->url() << ", poses from " << params.pose_channel << std::endl;
    std::map<std::string, std::int64_t> last_info_utime;
    std::uint64_t bad_poses = 0, frames = 0;
    auto subscription = nadir::core::subscribe<nadir::pose_t>(
        *bus, params.pose_channel, [&](const nadir::pose_t& pose) {
          Eigen::Isometry3d T_world_body;
          try {
            T_world_body = nadir::camera::bodyPoseFromMessage(pose);
          } catch (const std::invalid_argument& error) {
            if (bad_poses++ == 0) std::cerr << "dropping bad poses: " << error.what() << "\n";
            return;
          }
          for (const nadir::camera::CameraFrame& frame : rig.onPose(pose.utime, T_world_body)) {
            nadir::core::publish(
                *bus, frame.spec->channel,
                nadir::camera::toImageMessage(frame.rendered, frame.spec->jpeg_quality));
            // camera_info_t with the first frame, then once a second.
            auto& last = last_info_utime[frame.name];
            if (last == 0 || pose.utime - last >= 1'000'000 || pose.utime < last) {
              nadir::core::publish(
                  *bus, frame.spec->info_channel,
                  nadir::camera::toCameraInfo(frame.name, *frame.spec, rig.intrinsics(frame.name),
                                              pose.utime));
              last = pose.utime;
            }
            ++frames;
          }
        });
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    while (!g_stop) bus->handle(std::chrono::milliseconds(100));
    const auto stats = bus->stats();
    const auto pose_stats = stats.find(params.pose_channel);
    std::cout << "nadir-camera: published " << frames << " frames; dropped " << bad_poses
              << " bad poses and "
              << (pose_stats == stats.end() ? 0 : pose_stats->second.decode_errors)
              << " undecodable messages" << std::endl;
  } catch (const std::exception& error) {
    std::cerr << "nadir-camera: error: " << error.what() << std::endl;
    return 1;
  }
  return 0;
}
