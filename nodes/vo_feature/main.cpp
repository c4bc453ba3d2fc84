// nadir-vo-feature: the feature-based monocular VO as a live node: the
// downward camera's frames in, POSE_VO_FEATURE out. Wiring only.
//
//   nadir-vo-feature SCENARIO [--set key=value ...]   (the scenario's vo_feature group and bus)

#include <CLI/CLI.hpp>

#include <atomic>
#include <csignal>
#include <iostream>

#include "core/bus.h"
#include "nodes/vo_feature/vo_feature_node.h"
#include "scenario/scenario.h"

namespace {

std::atomic<bool> g_stop{false};

void onSignal(int) { g_stop = true; }

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"nadir-vo-feature: feature-based monocular visual odometry over LCM"};
  std::string scenario_name = "thesis-oscillating";
  std::vector<std::string> overrides;
  app.add_option("scenario", scenario_name, "built-in scenario name or YAML file")
      ->capture_default_str();
  app.add_option("--set", overrides, "override a parameter: key=value (repeatable)");
  CLI11_PARSE(app, argc, argv);

  try {
    nadir::scenario::ScenarioParams scenario =
        nadir::scenario::loadScenario(scenario_name, overrides);
    std::cout << "nadir-vo-feature parameters (" << scenario_name << ", vo_feature):\n"
              << nadir::core::formatParamsOf(scenario.vo_feature) << std::flush;
    auto bus = nadir::core::openBus(scenario.bus);
    nadir::vo::VoFeatureNode node(*bus, scenario.vo_feature);
    std::cout << "bus: " << bus->url() << ", frames from " << scenario.vo_feature.image_channel
              << std::endl;
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    while (!g_stop) bus->handle(std::chrono::milliseconds(100));
    if (node.droppedImages() > 0) {
      std::cerr << "nadir-vo-feature: dropped " << node.droppedImages()
                << " images; the first: " << node.firstDropReason() << "\n";
    }
    std::cout << "nadir-vo-feature: " << node.frames() << " frames, "
              << (node.frames() ? 1000.0 * node.processingSeconds() / node.frames() : 0.0)
              << " ms per frame" << std::endl;
  } catch (const std::exception& error) {
    std::cerr << "nadir-vo-feature: error: " << error.what() << std::endl;
    return 1;
  }
  return 0;
}
